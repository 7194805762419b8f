//! Mip chains built at upload (`Device::upload_image` on an image of several levels): every
//! level is the 2×2 box average of the level above (layer 0 read back; the blits cover every
//! layer at once), with the validation layer reporting nothing. The scene's texture arrays
//! are made this way.

mod common;

use shine::gpu::{Image, ImageDesc, vk};

/// The 2×2 box average of an RGBA8 level of `side` texels per side (what a linear blit to half
/// size samples: the corner shared by four texels).
fn halve(level: &[u8], side: usize) -> Vec<u8> {
    let half = side / 2;
    let mut out = Vec::with_capacity(half * half * 4);
    for y in 0..half {
        for x in 0..half {
            for c in 0..4 {
                let at = |dx: usize, dy: usize| {
                    f32::from(level[((2 * y + dy) * side + 2 * x + dx) * 4 + c])
                };
                out.push(((at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1)) / 4.0).round() as u8);
            }
        }
    }
    out
}

#[test]
fn every_level_is_the_box_average_of_the_one_above() {
    let device = common::device();
    let side = 16usize;
    let levels = 5;
    let layers = 2usize;
    let data: Vec<u8> = (0..side * side * 4 * layers)
        .map(|i| ((i * 7919 + (i / 4) * 131) % 251) as u8)
        .collect();
    let image = Image::new(
        &device,
        &ImageDesc {
            mip_levels: levels,
            array_layers: layers as u32,
            array_view: true,
            ..ImageDesc::new_2d(
                "mips",
                [side as u32; 2],
                vk::Format::R8G8B8A8_UNORM,
                vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::TRANSFER_DST
                    | vk::ImageUsageFlags::TRANSFER_SRC,
            )
        },
    )
    .expect("image");
    device
        .upload_image(&image, &data, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
        .expect("upload");
    let mut expected = data[..side * side * 4].to_vec();
    let mut size = side;
    for level in 1..levels {
        expected = halve(&expected, size);
        size /= 2;
        let got = device
            .read_image_level(&image, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL, level)
            .expect("read level");
        assert_eq!(got.len(), expected.len(), "level {level}");
        let worst = got
            .iter()
            .zip(&expected)
            .map(|(a, b)| a.abs_diff(*b))
            .max()
            .unwrap_or(0);
        // One halving of the GPU's own level above: the blit may round differently by one.
        assert!(worst <= 1, "level {level}: {worst}");
        expected = got;
    }
    assert!(
        device
            .read_image_level(&image, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL, levels)
            .is_err(),
        "a level past the chain must be refused"
    );
    common::assert_clean(&device);
}
