//! Bounds-checked accessor reading: every offset, stride and count is checked against the
//! buffer before a byte is read, so bad files give an error instead of a panic.

use gltf::accessor::{DataType, Dimensions};

/// Reads accessors out of the loaded buffers.
pub(crate) struct Buffers {
    /// Bytes of each glTF buffer, by index.
    pub(crate) data: Vec<Vec<u8>>,
}

/// Largest element count accepted for an accessor without a bufferView (all zeros, usually
/// a base for sparse values).
const MAX_VIEWLESS_ELEMENTS: usize = 1 << 26;

fn component_size(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// Reads component `i` of type `t` at the start of `b` as f32, applying glTF normalisation.
fn component(b: &[u8], t: DataType, normalized: bool) -> f32 {
    let get = |n: usize| -> [u8; 4] {
        let mut a = [0u8; 4];
        for (dst, src) in a.iter_mut().zip(b.iter().take(n)) {
            *dst = *src;
        }
        a
    };
    let a = get(component_size(t));
    match (t, normalized) {
        (DataType::F32, _) => f32::from_le_bytes(a),
        (DataType::U8, false) => f32::from(a[0]),
        (DataType::U8, true) => f32::from(a[0]) / 255.0,
        (DataType::I8, false) => f32::from(a[0] as i8),
        (DataType::I8, true) => (f32::from(a[0] as i8) / 127.0).max(-1.0),
        (DataType::U16, false) => f32::from(u16::from_le_bytes([a[0], a[1]])),
        (DataType::U16, true) => f32::from(u16::from_le_bytes([a[0], a[1]])) / 65535.0,
        (DataType::I16, false) => f32::from(i16::from_le_bytes([a[0], a[1]])),
        (DataType::I16, true) => (f32::from(i16::from_le_bytes([a[0], a[1]])) / 32767.0).max(-1.0),
        (DataType::U32, _) => u32::from_le_bytes(a) as f32,
    }
}

impl Buffers {
    /// The bytes of `count` elements of `elem_size` bytes at `offset` into `view`, as
    /// `(slice, stride)`; the message says which bound is violated.
    fn view_slice(
        &self,
        view: &gltf::buffer::View<'_>,
        offset: usize,
        count: usize,
        elem_size: usize,
    ) -> Result<(&[u8], usize), String> {
        let buffer = self
            .data
            .get(view.buffer().index())
            .ok_or_else(|| format!("buffer {} is missing", view.buffer().index()))?;
        let stride = view.stride().unwrap_or(elem_size);
        if stride < elem_size {
            return Err(format!(
                "bufferViews[{}] byteStride {stride} is smaller than an element ({elem_size} bytes)",
                view.index()
            ));
        }
        let view_end = view.offset().checked_add(view.length());
        let view_bytes = match view_end {
            Some(end) if end <= buffer.len() => buffer.get(view.offset()..end),
            _ => None,
        }
        .ok_or_else(|| {
            format!(
                "bufferViews[{}] (offset {}, length {}) runs past the end of buffers[{}] ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                buffer.len()
            )
        })?;
        let needed = if count == 0 {
            Some(offset)
        } else {
            (count - 1)
                .checked_mul(stride)
                .and_then(|x| x.checked_add(elem_size))
                .and_then(|x| x.checked_add(offset))
        };
        match needed {
            Some(n) if n <= view_bytes.len() => {
                Ok((view_bytes.get(offset..n).unwrap_or_default(), stride))
            }
            _ => Err(format!(
                "{count} elements of {elem_size} bytes (stride {stride}) at offset {offset} do not fit in bufferViews[{}] ({} bytes)",
                view.index(),
                view_bytes.len()
            )),
        }
    }

    /// Reads an accessor as `count` rows of `dimensions` f32 values (normalised integers are
    /// converted), sparse substitution included.
    pub(crate) fn read_f32(&self, acc: &gltf::Accessor<'_>) -> Result<(Vec<f32>, usize), String> {
        let dims = acc.dimensions().multiplicity();
        let t = acc.data_type();
        let csize = component_size(t);
        let elem = csize * dims;
        let count = acc.count();
        let mut out = match acc.view() {
            Some(view) => {
                let (bytes, stride) = self.view_slice(&view, acc.offset(), count, elem)?;
                let mut out = Vec::with_capacity(count * dims);
                if t == DataType::F32 {
                    for row in 0..count {
                        let start = row * stride;
                        let Some(e) = bytes.get(start..start + elem) else {
                            break;
                        };
                        out.extend(
                            e.chunks_exact(4)
                                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
                        );
                    }
                } else {
                    for row in 0..count {
                        let start = row * stride;
                        let Some(e) = bytes.get(start..start + elem) else {
                            break;
                        };
                        out.extend(
                            e.chunks_exact(csize)
                                .map(|c| component(c, t, acc.normalized())),
                        );
                    }
                }
                out
            }
            // No data to bound the count: refuse absurd sizes instead of aborting on the
            // allocation.
            None if count > MAX_VIEWLESS_ELEMENTS => {
                return Err(format!(
                    "accessor {} has no bufferView and {count} elements (more than {MAX_VIEWLESS_ELEMENTS})",
                    acc.index()
                ));
            }
            None => vec![0.0; count * dims],
        };
        if let Some(sparse) = acc.sparse() {
            let n = sparse.count();
            let iv = sparse.indices();
            let itype = match iv.index_type() {
                gltf::accessor::sparse::IndexType::U8 => DataType::U8,
                gltf::accessor::sparse::IndexType::U16 => DataType::U16,
                gltf::accessor::sparse::IndexType::U32 => DataType::U32,
            };
            let isize = component_size(itype);
            let (ibytes, _) = self.view_slice(&iv.view(), iv.offset(), n, isize)?;
            let vv = sparse.values();
            let (vbytes, _) = self.view_slice(&vv.view(), vv.offset(), n, elem)?;
            for k in 0..n {
                let idx =
                    component(ibytes.get(k * isize..).unwrap_or_default(), itype, false) as usize;
                let dst = out.get_mut(idx * dims..idx * dims + dims).ok_or_else(|| {
                    format!("sparse index {idx} is out of range for {count} elements")
                })?;
                let src = vbytes.get(k * elem..k * elem + elem).unwrap_or_default();
                for (d, c) in dst.iter_mut().zip(src.chunks_exact(csize)) {
                    *d = component(c, t, acc.normalized());
                }
            }
        }
        Ok((out, dims))
    }

    /// Reads an accessor of `expected` dimensions, or says what it holds instead.
    pub(crate) fn read_rows(
        &self,
        acc: &gltf::Accessor<'_>,
        expected: Dimensions,
    ) -> Result<Vec<f32>, String> {
        if acc.dimensions() != expected {
            return Err(format!(
                "accessor {} is {:?}, expected {:?}",
                acc.index(),
                acc.dimensions(),
                expected
            ));
        }
        self.read_f32(acc).map(|(v, _)| v)
    }

    /// Reads an index accessor (unsigned scalar).
    pub(crate) fn read_indices(&self, acc: &gltf::Accessor<'_>) -> Result<Vec<u32>, String> {
        let t = acc.data_type();
        if acc.dimensions() != Dimensions::Scalar
            || !matches!(t, DataType::U8 | DataType::U16 | DataType::U32)
        {
            return Err(format!(
                "index accessor {} must be an unsigned SCALAR, not {:?} {:?}",
                acc.index(),
                acc.dimensions(),
                t
            ));
        }
        if acc.sparse().is_some() {
            return self
                .read_f32(acc)
                .map(|(v, _)| v.into_iter().map(|x| x as u32).collect());
        }
        let size = component_size(t);
        let view = acc
            .view()
            .ok_or_else(|| format!("index accessor {} has no bufferView", acc.index()))?;
        let (bytes, stride) = self.view_slice(&view, acc.offset(), acc.count(), size)?;
        let mut out = Vec::with_capacity(acc.count());
        for row in 0..acc.count() {
            let s = row * stride;
            let v = match t {
                DataType::U8 => bytes.get(s).map(|&b| u32::from(b)),
                DataType::U16 => bytes
                    .get(s..s + 2)
                    .map(|b| u32::from(u16::from_le_bytes([b[0], b[1]]))),
                _ => bytes
                    .get(s..s + 4)
                    .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            };
            out.push(v.unwrap_or(0));
        }
        Ok(out)
    }
}
