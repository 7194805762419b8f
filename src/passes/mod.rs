//! The passes of a frame (docs/architecture.md, docs/frame.md): one module per pass, each adding its work
//! to a [`crate::graph::RenderGraph`] and returning its output handles, with a CPU reference of
//! the same computation for its GPU test where one exists.

pub mod aaf;
pub mod accumulate;
pub mod amortise;
pub mod brdf_tables;
pub mod composite;
pub mod cubes;
pub mod debug_view;
pub mod denoise;
pub mod direct;
pub mod environment_sh;
pub mod exposure;
pub mod gbuffer;
pub mod gi_add;
pub mod history;
pub mod host_gbuffer;
pub mod hvl;
pub mod igi;
pub mod path_trace;
pub mod proxy;
pub mod receivers;
pub mod rsm;
pub mod sample_history;
pub mod shadows;
pub mod sky;
pub mod specular;
pub mod traced_scene;
pub mod update_vertices;
pub mod upsample;

/// A pass parameter outside its range: the name, the value and the range in words.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("parameter `{name}` = {value} is out of range: {expected}")]
pub struct OutOfRange {
    /// Parameter name.
    pub name: &'static str,
    /// Value given.
    pub value: f64,
    /// The allowed range (`Debug` of the range constant: `1..=8`, `0.0..=10.0`).
    pub expected: String,
}

/// Checks `value` against the named range constant `range` (NaN is outside every range): the
/// one check of the passes' parameter validation.
pub fn check_range<T: PartialOrd + std::fmt::Debug + Into<f64> + Copy>(
    name: &'static str,
    value: T,
    range: &std::ops::RangeInclusive<T>,
) -> Result<(), OutOfRange> {
    if range.contains(&value) {
        Ok(())
    } else {
        Err(OutOfRange {
            name,
            value: value.into(),
            expected: format!("{range:?}"),
        })
    }
}
