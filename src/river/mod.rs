//! River networks (Chapter 5) and their samples (Section 6.4).

pub mod drainage;
pub mod hull;
pub mod network;
pub mod samples;
pub mod spline;
pub mod system;
