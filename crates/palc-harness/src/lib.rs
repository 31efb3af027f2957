//! Simulated users and the lesson-learning loop (paper Section II.A and Fig. 2):
//! plan, execute in traffic, let the user take over, learn, repeat.
