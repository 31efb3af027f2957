//! Road, vehicles and Intelligent Driver Model (IDM) background traffic for
//! personalized automated lane change (PALC).
//!
//! This crate will hold the paper's test bed (Section III.A): a two-lane road in
//! Frenet coordinates, vehicles following the IDM, the scenario grid of speed
//! cases and adjacent headways, and predictions of the surrounding vehicles over
//! a planning horizon.
