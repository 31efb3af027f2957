//! The driving experience aggregator: expert trajectories and reward correction
//! of the planner's weights (paper Eqs. 24-26 and 33-36), and the experience
//! store that carries what was learned into new scenarios.
