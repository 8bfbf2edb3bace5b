//! 1-D reduced harnesses of the paper's experiments (§5.1, §13): the wall harness of Fig. 4 and the
//! peg harness of Fig. 7. They share the force laws of [`haptic2d::laws`] with the 2-D world.

pub mod peg;
pub mod wall;
