//! Fig. 8–11 (placeholder).
