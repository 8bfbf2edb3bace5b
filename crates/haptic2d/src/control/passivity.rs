//! Passivity observer / passivity controller (Hannaford & Ryu 2002), §12.
