//! Small procedural textures for the built-in scenes, encoded as PNG.

use glam::Vec3;
use image::ImageEncoder;

/// Encodes `size`×`size` RGB pixels from `f(x, y)` (each channel 0..=1) as PNG.
fn png(size: u32, f: impl Fn(u32, u32) -> Vec3) -> Vec<u8> {
    let mut pixels = Vec::with_capacity((size * size * 3) as usize);
    for y in 0..size {
        for x in 0..size {
            let c = f(x, y).clamp(Vec3::ZERO, Vec3::ONE) * 255.0 + 0.5;
            pixels.extend([c.x as u8, c.y as u8, c.z as u8]);
        }
    }
    let mut out = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new(&mut out);
    // Encoding an in-memory buffer of the right size cannot fail.
    if encoder
        .write_image(&pixels, size, size, image::ExtendedColorType::Rgb8)
        .is_err()
    {
        out.clear();
    }
    out
}

/// Hash noise in 0..1 for an integer lattice point.
fn hash(x: u32, y: u32, seed: u32) -> f32 {
    let mut h =
        x.wrapping_mul(0x8DA6_B343) ^ y.wrapping_mul(0xD816_3841) ^ seed.wrapping_mul(0xCB1A_B31F);
    h ^= h >> 13;
    h = h.wrapping_mul(0x5BD1_E995);
    h ^= h >> 15;
    (h & 0xFFFF) as f32 / 65535.0
}

/// Tile layout: 4×4 tiles per texture, `grout` pixels wide; returns (tile id, distance in
/// pixels to the nearest grout edge, signed gradient direction of that edge).
fn tile(size: u32, x: u32, y: u32) -> (u32, f32, (f32, f32)) {
    let cell = size / 4;
    let (cx, cy) = (x % cell, y % cell);
    let id = (x / cell) + 4 * (y / cell);
    let dx = [
        (cx as f32 + 0.5, -1.0),
        (cell as f32 - cx as f32 - 0.5, 1.0),
    ];
    let dy = [
        (cy as f32 + 0.5, -1.0),
        (cell as f32 - cy as f32 - 0.5, 1.0),
    ];
    let ex = if dx[0].0 < dx[1].0 { dx[0] } else { dx[1] };
    let ey = if dy[0].0 < dy[1].0 { dy[0] } else { dy[1] };
    if ex.0 < ey.0 {
        (id, ex.0, (ex.1, 0.0))
    } else {
        (id, ey.0, (0.0, ey.1))
    }
}

const GROUT: f32 = 2.0;
const BEVEL: f32 = 3.0;

/// Floor tiles: terracotta tiles of varying shade with light grout (sRGB colour).
pub fn tiles_albedo(size: u32) -> Vec<u8> {
    png(size, |x, y| {
        let (id, d, _) = tile(size, x, y);
        if d < GROUT {
            return Vec3::splat(0.78);
        }
        let shade = 0.85 + 0.15 * hash(id, 0, 1) + 0.05 * hash(x, y, 2);
        Vec3::new(0.72, 0.42, 0.30) * shade
    })
}

/// Tangent-space normal map of the tiles: bevelled edges slope down into the grout.
pub fn tiles_normal(size: u32) -> Vec<u8> {
    png(size, |x, y| {
        let (_, d, (gx, gy)) = tile(size, x, y);
        let slope = if (GROUT..GROUT + BEVEL).contains(&d) {
            0.6
        } else {
            0.0
        };
        // Image y runs down, tangent-space +y (bitangent) runs up the texture: flip gy.
        let n = Vec3::new(gx * slope, -gy * slope, 1.0).normalize();
        n * 0.5 + 0.5
    })
}

/// Metallic (B) / roughness (G) of the tiles: glazed tiles glossy, grout rough.
pub fn tiles_metallic_roughness(size: u32) -> Vec<u8> {
    png(size, |x, y| {
        let (id, d, _) = tile(size, x, y);
        let roughness = if d < GROUT {
            0.9
        } else {
            0.2 + 0.15 * hash(id, 3, 4)
        };
        Vec3::new(0.0, roughness, 0.0)
    })
}

/// Plaster: off-white with soft blotches (sRGB colour).
pub fn plaster_albedo(size: u32) -> Vec<u8> {
    png(size, |x, y| {
        let n = 0.5 * hash(x / 8, y / 8, 5) + 0.3 * hash(x / 3, y / 3, 6) + 0.2 * hash(x, y, 7);
        Vec3::new(0.86, 0.84, 0.78) * (0.92 + 0.08 * n)
    })
}

/// A two-tone checkerboard (8×8 squares, sRGB colour).
pub fn checker(size: u32, a: Vec3, b: Vec3) -> Vec<u8> {
    let cell = (size / 8).max(1);
    png(size, |x, y| {
        if ((x / cell) + (y / cell)).is_multiple_of(2) {
            a
        } else {
            b
        }
    })
}
