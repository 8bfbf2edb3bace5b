//! The core crate's integration tests, one binary (issue 37: one link instead of one per file).
//! Each module is one former test file, named after what it checks; run one with
//! `cargo test -p haptic2d --test it MODULE::` (e.g. `passivity_random::`).
//! `impact_memory.rs` stays its own binary: its allocator measures the peak of every thread.

// The no-allocation modules count this thread's allocations (haptic2d-test-support).
haptic2d_test_support::install_counting_allocator!();
use haptic2d_test_support::alloc as counting_alloc;
#[path = "../support/polygon.rs"]
mod polygon_support;
#[path = "../support/ve.rs"]
mod ve_support;

mod collide_no_alloc;
mod collide_t1_t5;
mod common_fig4;
mod conformance_friction;
mod conformance_impacts;
mod conformance_impacts_truth;
mod contact_g1_g2;
mod contacts_truth;
mod control_x1_x3;
mod crossing_corners;
mod device_d1_d6;
mod device_params_files;
mod fixed_body_velocity;
mod fuzz_scene;
mod haptic_loop;
mod haptic_no_alloc;
mod haptic_prime;
mod impact_budget;
mod impact_friction;
mod impact_friction_no_alloc;
mod impact_i1_i5;
mod impact_sparse;
mod impact_surface_offset;
mod integrate_p1_p3;
mod local_reuse;
mod local_skip;
mod no_alloc;
mod passivity_port;
mod passivity_random;
mod pile_settle;
mod planar2_no_alloc;
mod planar2_safety;
mod planar2_twist;
mod proximity_partial;
mod proximity_spread;
mod repro_contacts;
mod safety_gate;
mod scene_bounds;
mod scene_errors;
mod shared;
mod stack_corners;
mod startup_ramp;
mod tunnelling;
mod workspace_bound;
mod world_f4;
mod world_pile;
