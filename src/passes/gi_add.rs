//! `gi_add`: the sum of two indirect-light images of one extent (`hvl,proxy` at receiver
//! resolution, `igi,proxy` and the specular reflections at full resolution).

use crate::graph::{Handle, Image, ImageDesc, RenderGraph, vk};
use crate::shaders;

/// Push constants of `shaders/gi_add.comp` (8 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AddPush {
    /// Image size.
    pub extent: [u32; 2],
}

/// Two images of different sizes were given to [`gi_add`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("gi_add: the second image is {second:?}, the first {first:?}: they must have one size")]
pub struct GiAddError {
    /// Width and height of the first image.
    pub first: [u32; 2],
    /// Width and height of the second image.
    pub second: [u32; 2],
}

/// Adds a pass named `name` (unique in the frame): `first + second` (RGBA16F images of one
/// extent) in a new image.
pub fn gi_add(
    rg: &mut RenderGraph,
    name: &str,
    first: &Handle<Image>,
    second: &Handle<Image>,
) -> Result<Handle<Image>, GiAddError> {
    let (a, b) = (first.desc().extent, second.desc().extent);
    if (a.width, a.height) != (b.width, b.height) {
        return Err(GiAddError {
            first: [a.width, a.height],
            second: [b.width, b.height],
        });
    }
    let mut sum = rg.create_image(
        "gi_sum",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, a.width, a.height),
    );
    rg.compute(name, &shaders::GI_ADD_COMP)
        .read("first", first)
        .read("second", second)
        .write("sum", &mut sum)
        .push(&AddPush {
            extent: [a.width, a.height],
        })
        .dispatch([a.width, a.height, 1]);
    Ok(sum)
}
