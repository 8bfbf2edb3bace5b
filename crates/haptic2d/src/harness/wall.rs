//! The 1-D wall harness (§5.1, §13.1).
