//! The dual-pantograph ("twin pantograph") planar haptic device (§10).
