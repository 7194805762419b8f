//! Vertex attribute generation: smooth normals and MikkTSpace tangents.

use glam::{Vec2, Vec3, Vec4};

/// Area-weighted smooth normals over the triangles sharing each vertex index. Vertices no
/// triangle touches (or only degenerate ones) get +Y.
pub(crate) fn smooth_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; positions.len()];
    for tri in indices.chunks_exact(3) {
        let [a, b, c] = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
        let (Some(&pa), Some(&pb), Some(&pc)) =
            (positions.get(a), positions.get(b), positions.get(c))
        else {
            continue;
        };
        // The cross product's length is twice the area: area weighting for free.
        let n = (pb - pa).cross(pc - pa);
        for i in [a, b, c] {
            if let Some(x) = acc.get_mut(i) {
                *x += n;
            }
        }
    }
    acc.into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
        .collect()
}

/// A unit tangent perpendicular to `n`, for surfaces without texture coordinates.
pub(crate) fn any_tangent(n: Vec3) -> Vec4 {
    n.any_orthonormal_vector().extend(1.0)
}

struct MikkInput<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    uvs: &'a [Vec2],
    indices: &'a [u32],
    /// One tangent per triangle corner.
    corners: Vec<Vec4>,
}

impl MikkInput<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.indices.get(face * 3 + vert).map_or(0, |&i| i as usize)
    }
}

impl bevy_mikktspace::Geometry for MikkInput<'_> {
    fn num_faces(&self) -> usize {
        self.indices.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions
            .get(self.vertex(face, vert))
            .copied()
            .unwrap_or_default()
            .to_array()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals
            .get(self.vertex(face, vert))
            .copied()
            .unwrap_or(Vec3::Y)
            .to_array()
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        // glTF's v runs down the image while its normal maps have +Y up the image, so the
        // bitangent must follow -v: MikkTSpace sees v flipped.
        let uv = self
            .uvs
            .get(self.vertex(face, vert))
            .copied()
            .unwrap_or_default();
        [uv.x, 1.0 - uv.y]
    }
    fn set_tangent(
        &mut self,
        tangent_space: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        if let (Some(ts), Some(slot)) = (tangent_space, self.corners.get_mut(face * 3 + vert)) {
            *slot = Vec4::from_array(ts.tangent_encoded());
        }
    }
}

/// Vertex arrays of one primitive, modified in place when tangents are generated.
pub(crate) struct VertexData {
    /// Positions.
    pub(crate) positions: Vec<Vec3>,
    /// Unit normals.
    pub(crate) normals: Vec<Vec3>,
    /// Texture coordinates.
    pub(crate) uvs: Vec<Vec2>,
    /// Triangle indices.
    pub(crate) indices: Vec<u32>,
}

/// MikkTSpace tangents in glTF's convention (bitangent = cross(normal, tangent) * w points
/// up the image, i.e. towards decreasing v). MikkTSpace works per triangle corner; where the corners sharing a
/// vertex disagree (UV seams, mirrored UVs) the vertex is duplicated so every corner keeps
/// its own tangent. Corners MikkTSpace leaves undefined (degenerate triangles) get a tangent
/// perpendicular to the normal.
///
/// Returns the tangents and, for each vertex appended by a split (in order), the index of
/// the vertex it copies, so other per-vertex data (joints, morph deltas) can follow.
pub(crate) fn mikktspace_tangents(v: &mut VertexData) -> (Vec<Vec4>, Vec<u32>) {
    let mut input = MikkInput {
        positions: &v.positions,
        normals: &v.normals,
        uvs: &v.uvs,
        indices: &v.indices,
        corners: vec![Vec4::ZERO; v.indices.len()],
    };
    let ok = bevy_mikktspace::generate_tangents(&mut input).is_ok();
    let corners = input.corners;
    let mut tangents: Vec<Option<Vec4>> = vec![None; v.positions.len()];
    let mut origins = Vec::new();
    for (corner, index) in v.indices.iter_mut().enumerate() {
        let vi = *index as usize;
        let normal = v.normals.get(vi).copied().unwrap_or(Vec3::Y);
        let t = corners
            .get(corner)
            .copied()
            .filter(|t| ok && t.truncate().length_squared() > 0.5 && t.is_finite())
            .unwrap_or_else(|| any_tangent(normal));
        match tangents.get(vi).copied().flatten() {
            None => {
                if let Some(slot) = tangents.get_mut(vi) {
                    *slot = Some(t);
                }
            }
            Some(existing)
                if existing.w == t.w && existing.truncate().dot(t.truncate()) > 0.999 => {}
            Some(_) => {
                // Split: a copy of the vertex carrying this corner's tangent.
                let new = v.positions.len() as u32;
                v.positions
                    .push(v.positions.get(vi).copied().unwrap_or_default());
                v.normals.push(normal);
                v.uvs.push(v.uvs.get(vi).copied().unwrap_or_default());
                tangents.push(Some(t));
                origins.push(vi as u32);
                *index = new;
            }
        }
    }
    let tangents = tangents
        .into_iter()
        .zip(&v.normals)
        .map(|(t, n)| t.unwrap_or_else(|| any_tangent(*n)))
        .collect();
    (tangents, origins)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_normals_of_a_tent_average_the_two_faces() {
        // Two triangles meeting at the ridge x = 0, tilted ±45°.
        let p = vec![
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let n = smooth_normals(&p, &[0, 1, 2, 1, 3, 2]);
        assert!((n[1] - Vec3::Y).length() < 1e-6, "{:?}", n[1]);
        assert!((n[0] - Vec3::new(-1.0, 1.0, 0.0).normalize()).length() < 1e-6);
    }

    #[test]
    fn tangents_follow_u_on_a_quad_and_split_mirrored_uvs() {
        let mut v = VertexData {
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(0.0, 0.0, -1.0),
            ],
            normals: vec![Vec3::Y; 4],
            uvs: vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 0.0),
            ],
            indices: vec![0, 1, 2, 0, 2, 3],
        };
        let (t, origins) = mikktspace_tangents(&mut v);
        assert_eq!(t.len(), 4);
        assert!(origins.is_empty());
        for t in &t {
            assert!((t.truncate() - Vec3::X).length() < 1e-5, "{t:?}");
            assert_eq!(t.w.abs(), 1.0);
        }
        // Mirror the second triangle's u: its corners get the opposite tangent.
        let mut m = VertexData {
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::ZERO,
                Vec3::new(1.0, 0.0, -1.0),
            ],
            normals: vec![Vec3::Y; 6],
            uvs: vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(0.0, 0.0),
            ],
            indices: vec![0, 1, 2, 4, 5, 3],
        };
        let (t, origins) = mikktspace_tangents(&mut m);
        assert_eq!(t.len(), m.positions.len());
        assert_eq!(origins.len(), m.positions.len() - 6);
        assert!((t[0].truncate() - Vec3::X).length() < 1e-5);
        assert!((t[4].truncate() + Vec3::X).length() < 1e-5, "{:?}", t[4]);
    }
}
