//! The lab's integration tests, one binary (issue 37: one link instead of one per file). Each module is one
//! former test file, named after what it checks; run one with
//! `cargo test -p haptic2d-lab --test it MODULE::`.

mod design_search;
mod fig5_coupling_pulse;
mod friction_models;
mod haptic_fig5;
mod haptic_fig8;
mod passivity_pc1_pc4;
mod peg_f7;
mod protocols_friction;
mod released_handle;
mod reproduce;
mod stability;
mod study_methods;
mod study_pse;
mod study_simulated;
mod study_support;
mod walls_w1_w9;
mod world_f7;
