//! Procedural triangle meshes for the built-in scenes (counter-clockwise front faces, as glTF).

use glam::{Mat4, Vec2, Vec3};

use crate::load::{VertexData, tangents_for};
use crate::types::{Aabb, Mesh, Primitive};

/// Indexed triangles with normals and UVs, before upload or export.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Positions.
    pub positions: Vec<Vec3>,
    /// Unit normals.
    pub normals: Vec<Vec3>,
    /// Texture coordinates.
    pub uvs: Vec<Vec2>,
    /// Triangle list.
    pub indices: Vec<u32>,
}

impl MeshData {
    /// Appends a planar quad with corners `a b c d` in counter-clockwise order seen from the
    /// front, UVs scaled by `uv_scale` (u along a→b, v along a→d, v pointing down the image).
    pub fn quad(&mut self, [a, b, c, d]: [Vec3; 4], uv_scale: Vec2) -> &mut Self {
        let n = (b - a).cross(d - a).normalize_or(Vec3::Y);
        let base = self.positions.len() as u32;
        self.positions.extend([a, b, c, d]);
        self.normals.extend([n; 4]);
        self.uvs.extend([
            Vec2::new(0.0, uv_scale.y),
            Vec2::new(uv_scale.x, uv_scale.y),
            Vec2::new(uv_scale.x, 0.0),
            Vec2::new(0.0, 0.0),
        ]);
        self.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        self
    }

    /// Appends another mesh.
    pub fn append(&mut self, other: &MeshData) -> &mut Self {
        let base = self.positions.len() as u32;
        self.positions.extend(&other.positions);
        self.normals.extend(&other.normals);
        self.uvs.extend(&other.uvs);
        self.indices.extend(other.indices.iter().map(|i| i + base));
        self
    }

    /// The mesh transformed by `m` (normals by its inverse transpose; a mirroring `m` keeps
    /// front faces counter-clockwise).
    pub fn transformed(mut self, m: Mat4) -> MeshData {
        let n = m.inverse().transpose();
        if m.determinant() < 0.0 {
            for t in self.indices.chunks_exact_mut(3) {
                t.swap(1, 2);
            }
        }
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        for v in &mut self.normals {
            *v = n.transform_vector3(*v).normalize_or(Vec3::Y);
        }
        self
    }

    /// Flips every triangle and normal (to see a box from the inside).
    pub fn flipped(mut self) -> MeshData {
        for t in self.indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
        for n in &mut self.normals {
            *n = -*n;
        }
        self
    }

    /// Bounds of the positions.
    pub fn bounds(&self) -> Aabb {
        self.positions.iter().fold(Aabb::EMPTY, |mut b, p| {
            b.grow(*p);
            b
        })
    }

    /// A one-primitive [`Mesh`] (tangents generated with MikkTSpace), for tests and fitting.
    pub fn into_mesh(self, name: &str, material: u32) -> Mesh {
        let bounds = self.bounds();
        let mut v = VertexData {
            positions: self.positions,
            normals: self.normals,
            uvs: self.uvs,
            indices: self.indices,
        };
        let tangents = tangents_for(&mut v);
        let VertexData {
            positions,
            normals,
            uvs,
            indices,
        } = v;
        Mesh {
            name: name.to_string(),
            primitives: vec![Primitive {
                positions,
                normals,
                tangents,
                uvs,
                indices,
                material,
                bounds,
                ..Primitive::default()
            }],
            weights: Vec::new(),
        }
    }
}

/// An axis-aligned box centred at the origin with edge lengths `size`, faces outward, each
/// face with its own vertices (flat normals) and UVs scaled to metres.
pub fn cuboid(size: Vec3) -> MeshData {
    let h = size * 0.5;
    let p = |x: f32, y: f32, z: f32| Vec3::new(x * h.x, y * h.y, z * h.z);
    let mut m = MeshData::default();
    m.quad(
        [
            p(-1., -1., 1.),
            p(1., -1., 1.),
            p(1., 1., 1.),
            p(-1., 1., 1.),
        ],
        Vec2::new(size.x, size.y),
    ) // +Z
    .quad(
        [
            p(1., -1., -1.),
            p(-1., -1., -1.),
            p(-1., 1., -1.),
            p(1., 1., -1.),
        ],
        Vec2::new(size.x, size.y),
    ) // -Z
    .quad(
        [
            p(1., -1., 1.),
            p(1., -1., -1.),
            p(1., 1., -1.),
            p(1., 1., 1.),
        ],
        Vec2::new(size.z, size.y),
    ) // +X
    .quad(
        [
            p(-1., -1., -1.),
            p(-1., -1., 1.),
            p(-1., 1., 1.),
            p(-1., 1., -1.),
        ],
        Vec2::new(size.z, size.y),
    ) // -X
    .quad(
        [
            p(-1., 1., 1.),
            p(1., 1., 1.),
            p(1., 1., -1.),
            p(-1., 1., -1.),
        ],
        Vec2::new(size.x, size.z),
    ) // +Y
    .quad(
        [
            p(-1., -1., -1.),
            p(1., -1., -1.),
            p(1., -1., 1.),
            p(-1., -1., 1.),
        ],
        Vec2::new(size.x, size.z),
    ); // -Y
    m
}

/// The floor (y = 0, texture repeats `w` × `d`) and ceiling (y = `h`, texture repeats
/// `ceiling_uv`) of a `w` × `d` room centred on the origin, both facing into the room (the
/// built-in rooms share them).
pub fn floor_and_ceiling(w: f32, d: f32, h: f32, ceiling_uv: Vec2) -> (MeshData, MeshData) {
    let (x, z) = (w * 0.5, d * 0.5);
    let c = Vec3::new;
    let mut floor = MeshData::default();
    floor.quad(
        [c(-x, 0., z), c(x, 0., z), c(x, 0., -z), c(-x, 0., -z)],
        Vec2::new(w, d),
    );
    let mut ceiling = MeshData::default();
    ceiling.quad(
        [c(-x, h, -z), c(x, h, -z), c(x, h, z), c(-x, h, z)],
        ceiling_uv,
    );
    (floor, ceiling)
}

/// A horizontal square of side `size` at y = 0 facing +Y, UVs repeating every `tile` metres.
pub fn ground(size: f32, tile: f32) -> MeshData {
    let h = size * 0.5;
    let mut m = MeshData::default();
    m.quad(
        [
            Vec3::new(-h, 0.0, h),
            Vec3::new(h, 0.0, h),
            Vec3::new(h, 0.0, -h),
            Vec3::new(-h, 0.0, -h),
        ],
        Vec2::splat(size / tile),
    );
    m
}

/// A UV sphere of `radius` with `segments` around and `rings` from pole to pole.
pub fn uv_sphere(radius: f32, segments: u32, rings: u32) -> MeshData {
    let mut m = MeshData::default();
    for r in 0..=rings {
        let v = r as f32 / rings as f32;
        let theta = v * std::f32::consts::PI;
        for s in 0..=segments {
            let u = s as f32 / segments as f32;
            let phi = u * std::f32::consts::TAU;
            let n = Vec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            );
            m.positions.push(n * radius);
            m.normals.push(n);
            m.uvs.push(Vec2::new(u, v));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let a = r * row + s;
            let b = a + row;
            if r != 0 {
                m.indices.extend([a, b, a + 1]);
            }
            if r + 1 != rings {
                m.indices.extend([a + 1, b, b + 1]);
            }
        }
    }
    m
}

/// A torus around +Y: ring radius `major`, tube radius `minor`.
pub fn torus(major: f32, minor: f32, segments: u32, sides: u32) -> MeshData {
    let mut m = MeshData::default();
    for i in 0..=segments {
        let u = i as f32 / segments as f32;
        let phi = u * std::f32::consts::TAU;
        let dir = Vec3::new(phi.sin(), 0.0, phi.cos());
        for j in 0..=sides {
            let v = j as f32 / sides as f32;
            let theta = v * std::f32::consts::TAU;
            let n = dir * theta.cos() + Vec3::Y * theta.sin();
            m.positions.push(dir * major + n * minor);
            m.normals.push(n);
            m.uvs.push(Vec2::new(u * 4.0, v));
        }
    }
    let row = sides + 1;
    for i in 0..segments {
        for j in 0..sides {
            let a = i * row + j;
            let b = a + row;
            m.indices.extend([a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every triangle's winding agrees with its vertex normals (front faces CCW).
    fn assert_outward(m: &MeshData) {
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            if face.length() < 1e-9 {
                continue;
            }
            let n = m.normals[t[0] as usize] + m.normals[t[1] as usize] + m.normals[t[2] as usize];
            assert!(
                face.dot(n) > 0.0,
                "triangle {t:?} winds against its normals"
            );
        }
    }

    #[test]
    fn shapes_wind_counter_clockwise_around_their_normals() {
        assert_outward(&cuboid(Vec3::new(1.0, 2.0, 3.0)));
        assert_outward(&ground(4.0, 1.0));
        assert_outward(&uv_sphere(1.0, 12, 8));
        assert_outward(&torus(1.0, 0.25, 16, 8));
        assert_outward(&cuboid(Vec3::ONE).flipped());
        assert_outward(
            &uv_sphere(1.0, 12, 8).transformed(
                Mat4::from_rotation_x(1.0) * Mat4::from_scale(Vec3::new(1.0, 2.0, -1.0)),
            ),
        );
    }
}
