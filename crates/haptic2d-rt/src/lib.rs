//! The real-time haptic loop of haptic2d.
