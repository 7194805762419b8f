//! The `shine` command-line tool.

fn main() {}
