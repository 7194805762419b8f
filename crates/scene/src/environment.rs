//! Environment lighting stored in a glTF file's root `extras`.
//!
//! glTF has no environment light, so shine reads one from the root object's extras:
//!
//! ```json
//! "extras": { "shine_environment": {
//!     "type": "sky",
//!     "zenith": [0.25, 0.45, 0.9], "horizon": [0.9, 0.9, 1.0], "ground": [0.3, 0.27, 0.22],
//!     "intensity": 1.0 } }
//! ```
//!
//! The sky is a distant radiance field over directions `d` (world space, +Y up), linear
//! Rec.709 RGB radiance in the same relative units as light intensities:
//! for `d.y >= 0`, `L(d) = intensity * mix(horizon, zenith, d.y^0.5)`;
//! for `d.y < 0`, `L(d) = intensity * mix(horizon, ground, (-d.y)^0.5)`.
//! It is smooth and low-frequency, which is what paper 002 lights with (projected to SH).
//!
//! Or an equirectangular map (`.hdr` or `.exr`, linear radiance), a path relative to the glTF
//! file, scaled by `intensity`:
//!
//! ```json
//! "extras": { "shine_environment": { "type": "map", "uri": "sky.hdr", "intensity": 1.0 } }
//! ```
//!
//! Direction `d` maps to `u = atan2(d.x, -d.z) / 2π + ½`, `v = acos(d.y) / π` (u across,
//! v down the image: the top row is straight up, the image centre looks down -Z), sampled
//! bilinearly, wrapping in u. [`Environment::load_map`] reads one from a file (`shine render
//! --environment FILE`).

use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use serde_json::{Value, json};

/// An equirectangular radiance map (linear RGB, row-major, top row = +Y).
#[derive(Clone, Debug, PartialEq)]
pub struct EquirectMap {
    /// Width in texels (the full circle of azimuth).
    pub width: u32,
    /// Height in texels (zenith to nadir).
    pub height: u32,
    /// `width × height` texels.
    pub texels: Arc<Vec<[f32; 3]>>,
    /// The URI or path it was read from (written back by [`Environment::to_json`]).
    pub uri: String,
}

impl EquirectMap {
    /// Reads a `.hdr` or `.exr` file; the error names the file and what is wrong.
    pub fn load(path: &Path, uri: &str) -> Result<EquirectMap, String> {
        let bytes = std::fs::read(path)
            .map_err(|e| format!("cannot read environment map {}: {e}", path.display()))?;
        Self::decode(&bytes, uri)
    }

    /// Decodes `.hdr` or `.exr` bytes (the format is sniffed from the contents; 8-bit formats
    /// are refused: they do not hold linear radiance).
    pub fn decode(bytes: &[u8], uri: &str) -> Result<EquirectMap, String> {
        match image::guess_format(bytes) {
            Ok(image::ImageFormat::Hdr | image::ImageFormat::OpenExr) => {}
            Ok(other) => {
                return Err(format!(
                    "environment map {uri:?} is {other:?}: only Radiance .hdr and OpenEXR .exr hold linear radiance"
                ));
            }
            Err(e) => return Err(format!("environment map {uri:?} cannot be decoded: {e}")),
        }
        let image = image::load_from_memory(bytes)
            .map_err(|e| format!("environment map {uri:?} cannot be decoded: {e}"))?
            .into_rgb32f();
        let (width, height) = image.dimensions();
        if width < 2 || height < 1 {
            return Err(format!(
                "environment map {uri:?} is {width}×{height}: too small"
            ));
        }
        let texels: Vec<[f32; 3]> = image
            .pixels()
            .map(|p| p.0.map(|c| if c.is_finite() { c.max(0.0) } else { 0.0 }))
            .collect();
        Ok(EquirectMap {
            width,
            height,
            texels: Arc::new(texels),
            uri: uri.to_string(),
        })
    }

    /// Bilinear radiance towards unit direction `d`.
    pub fn sample(&self, d: Vec3) -> Vec3 {
        let u = d.x.atan2(-d.z) / std::f32::consts::TAU + 0.5;
        let v = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
        let x = u * self.width as f32 - 0.5;
        let y = (v * self.height as f32 - 0.5).clamp(0.0, (self.height - 1) as f32);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let w = self.width as i64;
        let texel = |xi: i64, yi: f32| {
            let xi = xi.rem_euclid(w) as usize;
            let yi = (yi as usize).min(self.height as usize - 1);
            Vec3::from(self.texels[yi * self.width as usize + xi])
        };
        let (xa, xb) = (x0 as i64, x0 as i64 + 1);
        let top = texel(xa, y0).lerp(texel(xb, y0), fx);
        let bottom = texel(xa, y0 + 1.0).lerp(texel(xb, y0 + 1.0), fx);
        top.lerp(bottom, fy)
    }
}

/// The key in the root `extras` holding the environment.
pub const EXTRAS_KEY: &str = "shine_environment";

/// A procedural gradient sky, or an equirectangular map when `map` is set (see the module
/// documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// Radiance straight up.
    pub zenith: Vec3,
    /// Radiance at the horizon.
    pub horizon: Vec3,
    /// Radiance straight down.
    pub ground: Vec3,
    /// Multiplier on all three colours (and on the map).
    pub intensity: f32,
    /// An equirectangular map replacing the gradient.
    pub map: Option<EquirectMap>,
}

impl Environment {
    /// An environment of the map in `path` (`.hdr` or `.exr`) times `intensity`.
    pub fn load_map(path: &Path, intensity: f32) -> Result<Environment, String> {
        Ok(Environment {
            zenith: Vec3::ZERO,
            horizon: Vec3::ZERO,
            ground: Vec3::ZERO,
            intensity,
            map: Some(EquirectMap::load(path, &path.display().to_string())?),
        })
    }

    /// Radiance arriving from direction `dir` (need not be normalised).
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let d = dir.normalize_or(Vec3::Y);
        if let Some(map) = &self.map {
            return map.sample(d) * self.intensity;
        }
        let c = if d.y >= 0.0 {
            self.horizon.lerp(self.zenith, d.y.sqrt())
        } else {
            self.horizon.lerp(self.ground, (-d.y).sqrt())
        };
        c * self.intensity
    }

    /// The JSON stored under [`EXTRAS_KEY`].
    pub fn to_json(&self) -> Value {
        if let Some(map) = &self.map {
            return json!({"type": "map", "uri": map.uri, "intensity": self.intensity});
        }
        json!({
            "type": "sky",
            "zenith": self.zenith.to_array(),
            "horizon": self.horizon.to_array(),
            "ground": self.ground.to_array(),
            "intensity": self.intensity,
        })
    }

    /// Parses the value stored under [`EXTRAS_KEY`]; `fetch` reads a map's URI (relative to the
    /// glTF file). The error says which field is wrong.
    pub fn from_json(
        v: &Value,
        fetch: &dyn Fn(&str) -> Result<Vec<u8>, String>,
    ) -> Result<Environment, String> {
        let intensity = match v.get("intensity").map(|x| x.as_f64().map(|i| i as f32)) {
            None => 1.0,
            Some(Some(i)) if i.is_finite() && i >= 0.0 => i,
            Some(_) => {
                return Err("\"intensity\" must be a finite non-negative number".to_string());
            }
        };
        match v.get("type").and_then(Value::as_str) {
            Some("sky") => {}
            Some("map") => {
                let uri = v
                    .get("uri")
                    .and_then(Value::as_str)
                    .ok_or("a \"map\" environment needs a \"uri\" string")?;
                return Ok(Environment {
                    zenith: Vec3::ZERO,
                    horizon: Vec3::ZERO,
                    ground: Vec3::ZERO,
                    intensity,
                    map: Some(EquirectMap::decode(&fetch(uri)?, uri)?),
                });
            }
            Some(other) => {
                return Err(format!(
                    "unknown environment type {other:?} (expected \"sky\" or \"map\")"
                ));
            }
            None => return Err("missing \"type\": \"sky\" or \"map\"".to_string()),
        }
        let colour = |key: &str| -> Result<Vec3, String> {
            let a = v
                .get(key)
                .and_then(Value::as_array)
                .ok_or(format!("missing colour {key:?}"))?;
            let f: Vec<f32> = a
                .iter()
                .map(|x| x.as_f64().map_or(f32::NAN, |x| x as f32))
                .collect();
            match f.as_slice() {
                [r, g, b] if f.iter().all(|x| x.is_finite() && *x >= 0.0) => {
                    Ok(Vec3::new(*r, *g, *b))
                }
                _ => Err(format!("{key:?} must be three finite non-negative numbers")),
            }
        };
        Ok(Environment {
            zenith: colour("zenith")?,
            horizon: colour("horizon")?,
            ground: colour("ground")?,
            intensity,
            map: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn no_files(uri: &str) -> Result<Vec<u8>, String> {
        Err(format!("no file {uri}"))
    }

    #[test]
    fn json_round_trip_and_gradient_ends() {
        let e = Environment {
            zenith: Vec3::new(0.1, 0.2, 0.9),
            horizon: Vec3::ONE,
            ground: Vec3::splat(0.3),
            intensity: 2.0,
            map: None,
        };
        assert_eq!(
            Environment::from_json(&e.to_json(), &no_files),
            Ok(e.clone())
        );
        assert!((e.radiance(Vec3::Y) - e.zenith * 2.0).length() < 1e-6);
        assert!((e.radiance(Vec3::X) - e.horizon * 2.0).length() < 1e-6);
        assert!((e.radiance(-Vec3::Y) - e.ground * 2.0).length() < 1e-6);
        let short = json!({"type": "sky", "zenith": [1, 2]});
        assert!(Environment::from_json(&short, &no_files).is_err());
        let sky = |intensity: Value, zenith: Value| {
            json!({"type": "sky", "zenith": zenith, "horizon": [1, 1, 1], "ground": [1, 1, 1],
                   "intensity": intensity})
        };
        assert!(Environment::from_json(&sky(json!(1e39), json!([1, 1, 1])), &no_files).is_err());
        assert!(
            Environment::from_json(&sky(json!(1.0), json!(["a", 1, 1, 1])), &no_files).is_err()
        );
        let missing = json!({"type": "map", "uri": "sky.hdr"});
        let err = Environment::from_json(&missing, &no_files).unwrap_err();
        assert!(err.contains("no file sky.hdr"), "{err}");
    }

    /// An 8×4 EXR whose texel (x, y) holds (x, y, 1): sampled at every texel centre's
    /// direction the map gives that texel back, and the JSON names its URI.
    #[test]
    fn equirect_map_texel_centres_map_back_to_their_texels() {
        let (w, h) = (8u32, 4u32);
        let image = image::Rgb32FImage::from_fn(w, h, |x, y| image::Rgb([x as f32, y as f32, 1.0]));
        let mut bytes = std::io::Cursor::new(Vec::new());
        image::DynamicImage::ImageRgb32F(image)
            .write_to(&mut bytes, image::ImageFormat::OpenExr)
            .unwrap();
        let bytes = bytes.into_inner();
        let fetch = |uri: &str| {
            if uri == "sky.exr" {
                Ok(bytes.clone())
            } else {
                no_files(uri)
            }
        };
        let e = Environment::from_json(
            &json!({"type": "map", "uri": "sky.exr", "intensity": 2.0}),
            &fetch,
        )
        .unwrap();
        for y in 0..h {
            for x in 0..w {
                let phi = ((x as f32 + 0.5) / w as f32 - 0.5) * std::f32::consts::TAU;
                let theta = (y as f32 + 0.5) / h as f32 * std::f32::consts::PI;
                let d = Vec3::new(
                    theta.sin() * phi.sin(),
                    theta.cos(),
                    -theta.sin() * phi.cos(),
                );
                let got = e.radiance(d);
                let want = Vec3::new(x as f32, y as f32, 1.0) * 2.0;
                assert!(
                    (got - want).length() < 1e-3,
                    "texel ({x}, {y}): {got} vs {want}"
                );
            }
        }
        assert_eq!(e.to_json()["uri"], "sky.exr");
        assert!(EquirectMap::decode(b"not an image", "x.hdr").is_err());
        let mut png = std::io::Cursor::new(Vec::new());
        image::DynamicImage::ImageRgb8(image::RgbImage::new(4, 2))
            .write_to(&mut png, image::ImageFormat::Png)
            .unwrap();
        let err = EquirectMap::decode(&png.into_inner(), "sky.png").unwrap_err();
        assert!(err.contains("only Radiance .hdr and OpenEXR"), "{err}");
    }
}
