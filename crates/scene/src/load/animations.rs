//! Animations: translation, rotation and scale channels with their keys checked
//! (increasing finite times, one value per key, three for cubic splines).
//!
//! Read from the JSON: gltf 1.4's animation wrappers unwrap the target path and node, which
//! its validation does not check.

use glam::Vec4;
use gltf::accessor::Dimensions;
use gltf::json::animation::{Interpolation as I, Property as P};
use gltf::json::validation::Checked;

use super::accessor::Buffers;
use super::ctx::{Ctx, finite_rows};
use crate::animation::{Animation, Channel, Interpolation, Property};
use crate::error::Result;

/// Every animation of `doc`; channels driving morph target weights are left out with a
/// warning.
pub(super) fn load_animations(
    ctx: &mut Ctx,
    buffers: &Buffers,
    doc: &gltf::Document,
) -> Result<Vec<Animation>> {
    let mut out = Vec::new();
    let json = doc.as_json();
    for (ai, anim) in json.animations.iter().enumerate() {
        let name = anim
            .name
            .clone()
            .unwrap_or_else(|| format!("animation{ai}"));
        let mut channels = Vec::new();
        for (ci, ch) in anim.channels.iter().enumerate() {
            let element = format!("animations[{ai}] {name:?} channels[{ci}]");
            if let Some(channel) = load_channel(ctx, buffers, doc, anim, ch, &element)? {
                channels.push(channel);
            }
        }
        out.push(Animation { name, channels });
    }
    Ok(out)
}

/// One channel of `anim`, named `element` in messages; `None` (with a warning) for a
/// channel driving morph target weights.
fn load_channel(
    ctx: &mut Ctx,
    buffers: &Buffers,
    doc: &gltf::Document,
    anim: &gltf::json::Animation,
    ch: &gltf::json::animation::Channel,
    element: &str,
) -> Result<Option<Channel>> {
    let property = match &ch.target.path {
        Checked::Valid(P::Translation) => Property::Translation,
        Checked::Valid(P::Rotation) => Property::Rotation,
        Checked::Valid(P::Scale) => Property::Scale,
        Checked::Valid(P::MorphTargetWeights) => {
            ctx.warn(
                element,
                "animates morph target weights, which shine ignores",
            );
            return Ok(None);
        }
        Checked::Invalid => return Err(ctx.invalid(element, "unknown target path")),
    };
    let node = ch.target.node.value();
    if node >= doc.as_json().nodes.len() {
        return Err(ctx.invalid(element, format!("target node {node} does not exist")));
    }
    let sampler = anim.samplers.get(ch.sampler.value()).ok_or_else(|| {
        ctx.invalid(
            element,
            format!("sampler {} does not exist", ch.sampler.value()),
        )
    })?;
    let interpolation = match &sampler.interpolation {
        Checked::Valid(I::Step) => Interpolation::Step,
        Checked::Valid(I::Linear) => Interpolation::Linear,
        Checked::Valid(I::CubicSpline) => Interpolation::CubicSpline,
        Checked::Invalid => return Err(ctx.invalid(element, "unknown interpolation")),
    };
    let accessor = |index: usize, what: &str| {
        doc.accessors()
            .nth(index)
            .ok_or_else(|| ctx.invalid(element, format!("{what} accessor {index} does not exist")))
    };
    let input = accessor(sampler.input.value(), "input")?;
    let output = accessor(sampler.output.value(), "output")?;
    let times = key_times(ctx, buffers, &input, element)?;
    let values = key_values(
        ctx,
        buffers,
        &output,
        element,
        property,
        interpolation,
        times.len(),
    )?;
    Ok(Some(Channel {
        node,
        property,
        interpolation,
        times,
        values,
    }))
}

/// The key times in `input`: at least one, finite and strictly increasing.
fn key_times(
    ctx: &Ctx,
    buffers: &Buffers,
    input: &gltf::Accessor<'_>,
    element: &str,
) -> Result<Vec<f32>> {
    let times = buffers
        .read_rows(input, Dimensions::Scalar)
        .map_err(|m| ctx.invalid(format!("{element} input (accessors[{}])", input.index()), m))?;
    if times.is_empty()
        || times.iter().any(|t| !t.is_finite())
        || times.windows(2).any(|w| w[1] <= w[0])
    {
        return Err(ctx.invalid(
            element,
            "key times must be finite, strictly increasing and at least one",
        ));
    }
    Ok(times)
}

/// The key values in `output` for `keys` keys: finite, with the component count of
/// `property` (4 for rotations, 3 otherwise, `w` zero) and as many values per key as
/// `interpolation` needs (3 for cubic splines, 1 otherwise).
fn key_values(
    ctx: &Ctx,
    buffers: &Buffers,
    output: &gltf::Accessor<'_>,
    element: &str,
    property: Property,
    interpolation: Interpolation,
    keys: usize,
) -> Result<Vec<Vec4>> {
    let dims = if property == Property::Rotation { 4 } else { 3 };
    let (values, got) = buffers.read_f32(output).map_err(|m| {
        ctx.invalid(
            format!("{element} output (accessors[{}])", output.index()),
            m,
        )
    })?;
    if got != dims {
        return Err(ctx.invalid(
            element,
            format!("output has {got} components per key, expected {dims}"),
        ));
    }
    let per_key = if interpolation == Interpolation::CubicSpline {
        3
    } else {
        1
    };
    if values.len() / dims != keys * per_key {
        return Err(ctx.invalid(
            element,
            format!(
                "{} output values for {} keys (expected {} per key)",
                values.len() / dims,
                keys,
                per_key
            ),
        ));
    }
    finite_rows(ctx, element, "output", &values, dims, |c| {
        Vec4::new(c[0], c[1], c[2], c.get(3).copied().unwrap_or(0.0))
    })
}
