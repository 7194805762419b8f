//! Per-pass timing reports of `shine profile`.

pub mod report;
