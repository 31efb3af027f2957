//! The driving zone filter: a Gaussian discriminant analysis (GDA) model of the
//! user's perceived safe zone and the lateral bounds it implies (paper Eqs. 1-8
//! and 27-32).
//!
//! This crate depends on no other palc crate: plain numbers in, results out.
