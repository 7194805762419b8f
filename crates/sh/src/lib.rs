//! shine-sh: spherical-harmonics arithmetic for shine, the one trusted CPU implementation.
//!
//! Conventions (DESIGN §6): real orthonormal SH, index `l*l + l + m`, Condon–Shortley phase.
