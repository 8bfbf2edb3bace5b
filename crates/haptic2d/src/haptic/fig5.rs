//! Fig. 5–6 (placeholder).
