//! Contact records, the contact state machine, god-objects and simultaneous impacts (§7, §8).

pub mod impact;
pub mod lcp;
