//! Per-pass timing reports of `shine profile`, and the roofline that sets them against the
//! device's limits.

pub mod report;
pub mod roofline;
