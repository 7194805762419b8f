//! Compiles shaders/ to SPIR-V and reflects them (filled in by the foundation work).

fn main() {}
