//! Proxy spheres (paper 002): each dynamic object is approximated by a few spheres that block
//! and re-radiate light.
//!
//! [`fit`] places K spheres on a mesh: Lloyd's k-means (k-means++ seeding) over area-weighted
//! surface samples gives the centres, and each radius is the distance to the farthest sample
//! or vertex assigned to that centre, so the spheres cover the surface. The fit is
//! deterministic (fixed-seed sampling). [`coverage`] measures how well spheres stand for a
//! mesh on an independent sample set.
//!
//! Explicit proxies in a node's glTF `extras` override the fit:
//! `{"shine_proxies": [{"center": [x, y, z], "radius": r}, ...]}` with centres in the node's
//! local space and radii in its local units. Proxies follow their node's animation
//! ([`crate::Scene::proxies_at`]).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use serde_json::{Value, json};

use crate::types::Mesh;

/// The key in a node's `extras` holding explicit proxies.
pub const EXTRAS_KEY: &str = "shine_proxies";
/// Number of spheres fitted to an animated mesh without explicit proxies.
pub const DEFAULT_PROXY_COUNT: usize = 4;

const FIT_SAMPLES: usize = 2048;
const CHECK_SAMPLES: usize = 4096;
const KMEANS_ITERATIONS: usize = 24;

/// A sphere, laid out for a GPU buffer (16 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct ProxySphere {
    /// Centre.
    pub center: [f32; 3],
    /// Radius.
    pub radius: f32,
}

impl ProxySphere {
    /// The sphere carried by the node matrix `world`: its centre transformed, its radius scaled
    /// by the matrix's largest axis scale (so it still bounds what it stood for).
    pub fn transformed(&self, world: &Mat4) -> ProxySphere {
        let scale = world
            .x_axis
            .truncate()
            .length()
            .max(world.y_axis.truncate().length())
            .max(world.z_axis.truncate().length());
        ProxySphere {
            center: world.transform_point3(Vec3::from(self.center)).to_array(),
            radius: self.radius * scale,
        }
    }
}

/// How well a set of spheres stands for a mesh surface, measured on area-weighted surface
/// samples independent of the ones used to fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coverage {
    /// Fraction of surface samples outside every sphere (0 = the spheres cover the surface).
    pub uncovered: f32,
    /// Root mean square distance, in the mesh's units, from a surface sample to the boundary
    /// of the union of spheres (`min_i |p - c_i| - r_i`): how closely the spheres hug the
    /// surface. Lower is tighter.
    pub rms_distance: f32,
}

/// Where a node's proxies come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProxySource {
    /// Given in the node's `extras`.
    Explicit,
    /// Fitted to the node's mesh, with the fit's coverage.
    Fitted(Coverage),
}

/// The proxy spheres of one node, in the node's local space.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeProxies {
    /// Node index.
    pub node: usize,
    /// Spheres in node-local space.
    pub spheres: Vec<ProxySphere>,
    /// Explicit or fitted.
    pub source: ProxySource,
}

/// Spheres fitted to a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The spheres, in mesh space.
    pub spheres: Vec<ProxySphere>,
    /// Their coverage of the mesh.
    pub error: Coverage,
}

/// A small deterministic generator (SplitMix64) so fits are reproducible.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// `n` points on the mesh surface, uniform by area.
fn surface_samples(mesh: &Mesh, n: usize, seed: u64) -> Vec<Vec3> {
    let mut tris: Vec<[Vec3; 3]> = Vec::new();
    for p in &mesh.primitives {
        for t in p.indices.chunks_exact(3) {
            let get = |i: u32| p.positions.get(i as usize).copied();
            if let (Some(a), Some(b), Some(c)) = (get(t[0]), get(t[1]), get(t[2])) {
                tris.push([a, b, c]);
            }
        }
    }
    let mut cdf = Vec::with_capacity(tris.len());
    let mut total = 0.0f64;
    for [a, b, c] in &tris {
        total += f64::from((*b - *a).cross(*c - *a).length() * 0.5);
        cdf.push(total);
    }
    if tris.is_empty() {
        return Vec::new();
    }
    let mut rng = Rng(seed);
    (0..n)
        .map(|i| {
            // Degenerate meshes (zero area) fall back to cycling through the triangles.
            let k = if total > 0.0 {
                let x = f64::from(rng.next_f32()) * total;
                cdf.partition_point(|&c| c <= x).min(tris.len() - 1)
            } else {
                i % tris.len()
            };
            let [a, b, c] = tris.get(k).copied().unwrap_or([Vec3::ZERO; 3]);
            let (mut u, mut v) = (rng.next_f32(), rng.next_f32());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            a + (b - a) * u + (c - a) * v
        })
        .collect()
}

fn nearest(centers: &[Vec3], p: Vec3) -> usize {
    let mut best = (0, f32::INFINITY);
    for (i, c) in centers.iter().enumerate() {
        let d = c.distance_squared(p);
        if d < best.1 {
            best = (i, d);
        }
    }
    best.0
}

/// Fits `k` spheres (fewer if the mesh has fewer distinct sample points) covering `mesh`.
pub fn fit(mesh: &Mesh, k: usize) -> Fit {
    let samples = surface_samples(mesh, FIT_SAMPLES, 0x5348_494E_4531);
    let Some(&first) = samples.first() else {
        return Fit {
            spheres: Vec::new(),
            error: Coverage {
                uncovered: 0.0,
                rms_distance: 0.0,
            },
        };
    };
    let mut rng = Rng(0x4B4D_4541_4E53);
    // k-means++ seeding.
    let mut centers = vec![first];
    let mut d2: Vec<f32> = samples.iter().map(|s| s.distance_squared(first)).collect();
    while centers.len() < k.max(1) {
        let total: f32 = d2.iter().sum();
        if total <= 0.0 {
            break;
        }
        let mut x = rng.next_f32() * total;
        let mut pick = samples.len() - 1;
        for (i, d) in d2.iter().enumerate() {
            x -= d;
            if x <= 0.0 {
                pick = i;
                break;
            }
        }
        let c = samples.get(pick).copied().unwrap_or(first);
        centers.push(c);
        for (d, s) in d2.iter_mut().zip(&samples) {
            *d = d.min(s.distance_squared(c));
        }
    }
    // Lloyd iterations.
    let mut assign = vec![0usize; samples.len()];
    for _ in 0..KMEANS_ITERATIONS {
        let mut changed = false;
        for (a, s) in assign.iter_mut().zip(&samples) {
            let n = nearest(&centers, *s);
            changed |= *a != n;
            *a = n;
        }
        let mut sum = vec![(Vec3::ZERO, 0u32); centers.len()];
        for (a, s) in assign.iter().zip(&samples) {
            if let Some(slot) = sum.get_mut(*a) {
                slot.0 += *s;
                slot.1 += 1;
            }
        }
        for (c, (s, n)) in centers.iter_mut().zip(&sum) {
            if *n > 0 {
                *c = *s / *n as f32;
            }
        }
        if !changed {
            break;
        }
    }
    // Radii cover every sample and vertex assigned to each centre.
    let mut radius = vec![0.0f32; centers.len()];
    let vertices = mesh
        .primitives
        .iter()
        .flat_map(|p| p.positions.iter().copied());
    for p in samples.iter().copied().chain(vertices) {
        let n = nearest(&centers, p);
        if let (Some(r), Some(c)) = (radius.get_mut(n), centers.get(n)) {
            *r = r.max(c.distance(p));
        }
    }
    let spheres: Vec<ProxySphere> = centers
        .iter()
        .zip(&radius)
        .filter(|(_, r)| **r > 0.0)
        .map(|(c, r)| ProxySphere {
            center: c.to_array(),
            radius: *r * 1.0001,
        })
        .collect();
    let error = coverage(mesh, &spheres);
    Fit { spheres, error }
}

/// Coverage of `mesh` by `spheres` (both in the same space).
pub fn coverage(mesh: &Mesh, spheres: &[ProxySphere]) -> Coverage {
    let samples = surface_samples(mesh, CHECK_SAMPLES, 0x434F_5645_5241);
    if samples.is_empty() {
        return Coverage {
            uncovered: 0.0,
            rms_distance: 0.0,
        };
    }
    let scale = mesh.bounds().extent().length().max(1e-6);
    let mut outside = 0usize;
    let mut sum2 = 0.0f64;
    for p in &samples {
        let d = spheres
            .iter()
            .map(|s| Vec3::from(s.center).distance(*p) - s.radius)
            .fold(f32::INFINITY, f32::min);
        if d > 1e-5 * scale {
            outside += 1;
        }
        let d = if d.is_finite() { d } else { scale };
        sum2 += f64::from(d * d);
    }
    Coverage {
        uncovered: outside as f32 / samples.len() as f32,
        rms_distance: (sum2 / samples.len() as f64).sqrt() as f32,
    }
}

/// The JSON array stored under [`EXTRAS_KEY`].
pub fn to_json(spheres: &[ProxySphere]) -> Value {
    Value::Array(
        spheres
            .iter()
            .map(|s| json!({"center": s.center, "radius": s.radius}))
            .collect(),
    )
}

/// Parses the array stored under [`EXTRAS_KEY`]; the error names the bad entry.
pub fn from_json(v: &Value) -> Result<Vec<ProxySphere>, String> {
    let list = v
        .as_array()
        .ok_or("must be an array of {\"center\": [x, y, z], \"radius\": r}")?;
    list.iter()
        .enumerate()
        .map(|(i, s)| {
            let center: Vec<f32> = s
                .get("center")
                .and_then(Value::as_array)
                .map(|a| a.iter().filter_map(Value::as_f64).map(|x| x as f32).collect())
                .unwrap_or_default();
            let radius = s.get("radius").and_then(Value::as_f64).map(|r| r as f32);
            match (center.as_slice(), radius) {
                ([x, y, z], Some(r)) if center.iter().all(|c| c.is_finite()) && r.is_finite() && r > 0.0 => {
                    Ok(ProxySphere { center: [*x, *y, *z], radius: r })
                }
                _ => Err(format!("entry {i} needs \"center\": three finite numbers and \"radius\": a positive number")),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::shapes;

    #[test]
    fn one_sphere_fits_a_sphere_tightly() {
        let mesh = shapes::uv_sphere(0.5, 24, 16).into_mesh("ball", 0);
        let f = fit(&mesh, 1);
        assert_eq!(f.spheres.len(), 1);
        let s = f.spheres[0];
        assert!(Vec3::from(s.center).length() < 0.02, "{s:?}");
        assert!((s.radius - 0.5).abs() < 0.02, "{s:?}");
        assert_eq!(f.error.uncovered, 0.0);
        assert!(f.error.rms_distance < 0.02);
    }

    #[test]
    fn more_spheres_hug_a_long_box_better_and_cover_it() {
        let mesh = shapes::cuboid(Vec3::new(4.0, 0.5, 0.5)).into_mesh("bar", 0);
        let one = fit(&mesh, 1);
        let four = fit(&mesh, 4);
        assert_eq!(four.spheres.len(), 4);
        assert!(
            four.error.rms_distance < one.error.rms_distance * 0.5,
            "{one:?} {four:?}"
        );
        assert!(four.error.uncovered < 0.01, "{four:?}");
        // A sphere that covers nothing leaves everything uncovered.
        let tiny = coverage(
            &mesh,
            &[ProxySphere {
                center: [0.0; 3],
                radius: 0.01,
            }],
        );
        assert_eq!(tiny.uncovered, 1.0);
    }

    #[test]
    fn json_round_trip_and_rejects_bad_entries() {
        let s = vec![ProxySphere {
            center: [1.0, 2.0, 3.0],
            radius: 0.5,
        }];
        assert_eq!(from_json(&to_json(&s)), Ok(s));
        assert!(from_json(&json!([{"center": [0, 0], "radius": 1}])).is_err());
        assert!(from_json(&json!([{"center": [0, 0, 0], "radius": -1}])).is_err());
        assert!(from_json(&json!({"center": [0, 0, 0]})).is_err());
    }
}
