//! Contact laws: normal laws (virtual walls, §5) and friction models (§1–§4), each behind a small trait.
//!
//! Every law works on one vertex–edge (VE) contact, or on the 1-D wall/peg harnesses, through plain
//! input structs; the world never needs to know which model it is running.

mod declare;
pub mod friction;
pub mod normal;
pub mod params;
mod stiffness;
