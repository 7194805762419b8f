//! Animations: translation, rotation, scale and morph weight channels with their keys
//! checked (increasing finite times, one value per key, three for cubic splines; weight
//! values as many per key as the target node's mesh has morph targets).
//!
//! Read from the JSON: gltf 1.4's animation wrappers unwrap the target path and node, which
//! its validation does not check.

use gltf::accessor::Dimensions;
use gltf::json::animation::{Interpolation as I, Property as P};
use gltf::json::validation::Checked;

use super::accessor::Buffers;
use super::ctx::{Ctx, finite_rows};
use crate::animation::{Animation, Channel, Interpolation, Property};
use crate::error::Result;

/// Every animation of `doc`.
pub(super) fn load_animations(
    ctx: &Ctx,
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
            channels.push(load_channel(ctx, buffers, doc, anim, ch, &element)?);
        }
        out.push(Animation { name, channels });
    }
    Ok(out)
}

/// One channel of `anim`, named `element` in messages.
fn load_channel(
    ctx: &Ctx,
    buffers: &Buffers,
    doc: &gltf::Document,
    anim: &gltf::json::Animation,
    ch: &gltf::json::animation::Channel,
    element: &str,
) -> Result<Channel> {
    let property = match &ch.target.path {
        Checked::Valid(P::Translation) => Property::Translation,
        Checked::Valid(P::Rotation) => Property::Rotation,
        Checked::Valid(P::Scale) => Property::Scale,
        Checked::Valid(P::MorphTargetWeights) => Property::Weights,
        Checked::Invalid => return Err(ctx.invalid(element, "unknown target path")),
    };
    let node = ch.target.node.value();
    let Some(target) = doc.nodes().nth(node) else {
        return Err(ctx.invalid(element, format!("target node {node} does not exist")));
    };
    let width = match property {
        Property::Rotation => 4,
        Property::Translation | Property::Scale => 3,
        Property::Weights => {
            let targets = target
                .mesh()
                .and_then(|m| m.primitives().next())
                .map_or(0, |p| p.morph_targets().count());
            if targets == 0 {
                return Err(ctx.invalid(
                    element,
                    format!("animates the weights of node {node}, whose mesh has no morph targets"),
                ));
            }
            targets
        }
    };
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
        (property, width),
        interpolation,
        times.len(),
    )?;
    Ok(Channel {
        node,
        property,
        interpolation,
        times,
        width,
        values,
    })
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

/// The key values in `output` for `keys` keys, flat: finite, `width` floats per value (4
/// for rotations, 3 for translations and scales, one per morph target for weights, which
/// the file stores as SCALARs) and as many values per key as `interpolation` needs (3 for
/// cubic splines, 1 otherwise).
fn key_values(
    ctx: &Ctx,
    buffers: &Buffers,
    output: &gltf::Accessor<'_>,
    element: &str,
    (property, width): (Property, usize),
    interpolation: Interpolation,
    keys: usize,
) -> Result<Vec<f32>> {
    let (values, got) = buffers.read_f32(output).map_err(|m| {
        ctx.invalid(
            format!("{element} output (accessors[{}])", output.index()),
            m,
        )
    })?;
    // Weights are SCALAR rows, `width` of them per value; the others one row per value.
    let expected = if property == Property::Weights {
        1
    } else {
        width
    };
    if got != expected {
        return Err(ctx.invalid(
            element,
            format!("output has {got} components per row, expected {expected}"),
        ));
    }
    let per_key = if interpolation == Interpolation::CubicSpline {
        3
    } else {
        1
    };
    if values.len() / width != keys * per_key || !values.len().is_multiple_of(width) {
        return Err(ctx.invalid(
            element,
            format!(
                "{} output values of {width} components for {keys} keys (expected {per_key} per key)",
                values.len() / width
            ),
        ));
    }
    finite_rows(ctx, element, "output", &values, width, |_| ())?;
    Ok(values)
}
