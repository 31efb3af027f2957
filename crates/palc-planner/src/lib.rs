//! The lane-change trajectory planner: a linear time-varying model predictive
//! controller solved as a convex quadratic program (paper Eqs. 9-23 and 34).
//!
//! This crate depends on no other palc crate: plain numbers in, results out.
