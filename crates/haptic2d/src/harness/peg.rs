//! The 1-D peg-in-hole friction harness (§13.2).
