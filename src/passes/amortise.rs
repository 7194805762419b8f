//! GI amortised over frames (paper 001, "GI need not update every frame"), for any technique
//! whose light is shaded per pixel: HVL's gather, the proxies' occlusion, IGI's VPL sets and
//! AAF's samples (`hvl.slices`, `proxy.slices`, `igi.slices`, `aaf.slices` = [`SLICES`]).
//!
//! A technique refreshes one pixel of every 2×2 cell per frame, in turn ([`Schedule`] picks
//! the cell's pixel, [`slice_of_frame`]); `*_resolve` (shaders/amortise.comp) carries the other
//! three over from the previous frame's resolved light, reprojected with the G-buffer's motion
//! vectors, and rejects history where the surface was not visible then (depth or normal too
//! different): `*_regather_mask` marks those pixels (alpha −1 in the fresh light) and the
//! technique shades them again the same frame with [`REGATHER_SLICE`] (paper 001's priority
//! refresh of what moved). What a moving light or object changed is refreshed at once too: a
//! cell whose refreshed pixel changed by more than [`RESOLVE_CHANGE_LIMIT`] takes that pixel's
//! light (or, where it shows another surface, is shaded again); a technique amortised by its
//! records regathers every pixel of a block of [`RECORD_BLOCK`]² whose refreshed records'
//! summed signal changed beyond the limit ([`RecordSignal`]). What a change does not reach
//! stays amortised.
//! Refreshed pixels blend fresh light into valid history ([`RESOLVE_ALPHA`]), or take it where
//! it changed beyond the limit; the others keep theirs, changed by the change their cell's
//! refreshed pixel makes. Tried and dropped for HVL (docs/quality.md): filling disocclusions from the
//! cell's fresh value, pulling every pixel towards it each frame, and filling from the nearest
//! of nine refreshed pixels; all flickered more than the per-frame gather. CPU twin:
//! [`crate::reference::resolve::resolve_cpu`]. The GLSL side of a slice (which pixel a thread
//! shades) is `amortise_pixel` in shaders/include/amortise.glsl.

use glam::Vec3;

use crate::graph::{Buffer, BufferDesc, History, Image, ImageDesc, RenderGraph, vk};
use crate::passes::gbuffer::GBuffer;
use crate::passes::receivers::Receivers;
use crate::shaders;
use shine_graph::Handle;

/// Weight of the fresh light at a refreshed pixel whose history is valid (an exponential
/// history: lag of about 1/α refreshes, less flicker).
pub const RESOLVE_ALPHA: f32 = 0.5;
/// Largest relative difference of linear depth between a pixel and its history.
pub const RESOLVE_DEPTH_TOLERANCE: f32 = 0.1;
/// Smallest cosine between a pixel's normal and its history's.
pub const RESOLVE_NORMAL_COS: f32 = 0.9;
/// Largest change of a cell's refreshed pixel (or a block's summed records), relative to the
/// brighter of its value now and in its history ([`changed`]), before the cell's other pixels
/// take the new light the same frame (paper 001's priority refresh of what a moving light or
/// object affects); below it they follow the change (docs/quality.md, 0.25 against 0.5).
pub const RESOLVE_CHANGE_LIMIT: f32 = 0.5;
/// Side of the square block of pixels whose refreshed records' signals `*_reproject`'s change
/// test sums (4×4 cells): one record is one pixel's noisy estimate (IGI's VPL subset, AAF's
/// samples), their sum over a block follows the light (`AMORTISE_RECORD_BLOCK`).
pub const RECORD_BLOCK: u32 = 8;
/// Pixels per refresh cell (2×2): an amortised technique shades one of them per frame.
pub const SLICES: u32 = 4;
/// The slice that shades only the pixels `*_regather_mask` marked
/// (`AMORTISE_REGATHER_SLICE` in shaders/include/amortise.glsl).
pub const REGATHER_SLICE: u32 = SLICES + 1;
/// The slice counts a technique's `slices` setting takes: every pixel every frame, or one of
/// every 2×2 cell.
pub const SLICE_CHOICES: [u32; 2] = [1, SLICES];

/// Whether history at `depth_then` with normal `n_then` shows the same surface as a pixel at
/// `depth` with unit normal `n` (`resolve_same_surface` in shaders/include/amortise.glsl).
pub fn same_surface(depth: f32, n: Vec3, depth_then: f32, n_then: Vec3) -> bool {
    depth_then > 0.0
        && (depth_then - depth).abs() <= RESOLVE_DEPTH_TOLERANCE * depth
        && n.dot(n_then) >= RESOLVE_NORMAL_COS * n_then.length()
}

/// Whether light `now` differs from `then`, in any channel, by more than
/// [`RESOLVE_CHANGE_LIMIT`] of the brightest channel of either (`amortise_changed` in
/// shaders/include/amortise.glsl).
pub fn changed(now: Vec3, then: Vec3) -> bool {
    let big = now.abs().max(then.abs()).max_element();
    (now - then).abs().max_element() > RESOLVE_CHANGE_LIMIT * big
}

/// The refreshed pixel of every cell in frame `frame`: its offset index k (x = k & 1,
/// y = k >> 1), as the slice `1 + k` the passes take.
pub fn slice_of_frame(frame: u64) -> u32 {
    1 + (frame % u64::from(SLICES)) as u32
}

/// Where the refreshed pixel of every 2×2 cell is in slice 1 + k: (k & 1, k >> 1)
/// (`amortise_offset` in shaders/include/amortise.glsl).
pub fn slice_offset(slice: u32) -> [u32; 2] {
    let k = slice.saturating_sub(1);
    [k & 1, k >> 1]
}

/// Whether pixel (x, y) is the refreshed one of its cell in `slice` (true for slice 0;
/// `amortise_refreshed`).
pub fn refreshed(slice: u32, x: u32, y: u32) -> bool {
    slice == 0 || [x & 1, y & 1] == slice_offset(slice)
}

/// Threads a pass dispatches to shade `slice` of an `extent` image: every pixel for slice 0
/// and [`REGATHER_SLICE`], one per 2×2 cell otherwise (`amortise_pixel` maps them).
pub fn slice_threads(extent: [u32; 2], slice: u32) -> [u32; 3] {
    if slice == 0 || slice == REGATHER_SLICE {
        [extent[0], extent[1], 1]
    } else {
        [extent[0].div_ceil(2), extent[1].div_ceil(2), 1]
    }
}

/// Which frame an amortised technique last resolved, so the next one knows whether its history
/// holds the previous frame. Without it (first frame, a resize, a frame skipped, the setting
/// just turned on, another record layout) the technique shades every pixel (slice 0).
#[derive(Debug, Default)]
pub struct Schedule {
    /// Frame number, image extent and record layout of the last frame that resolved into the
    /// history.
    last: Option<(u64, [u32; 2], u32)>,
}

/// This frame's slice of an amortised technique.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slice {
    /// 0: every pixel; 1 + k: the pixel at (k & 1, k >> 1) of every 2×2 cell.
    pub slice: u32,
    /// Whether the history holds the previous frame.
    pub has_history: bool,
}

impl Schedule {
    /// The slice of `frame` for a technique of `slices` (1: not amortised, `None`) shading
    /// images of `extent`, whose history holds records of `layout` (e.g. uints per pixel; 0
    /// for a light history): another layout than the last frame's is no history.
    pub fn next(
        &mut self,
        frame: u64,
        extent: [u32; 2],
        slices: u32,
        layout: u32,
    ) -> Option<Slice> {
        if slices <= 1 {
            self.last = None;
            return None;
        }
        let has_history = self.last == Some((frame.wrapping_sub(1), extent, layout));
        self.last = Some((frame, extent, layout));
        Some(Slice {
            slice: if has_history {
                slice_of_frame(frame)
            } else {
                0
            },
            has_history,
        })
    }

    /// Forgets the history (a new scene, a frame dropped unrun).
    pub fn reset(&mut self) {
        self.last = None;
    }
}

/// The surfaces an amortised light is resolved over: receivers (HVL, proxies) or the
/// full-resolution G-buffer (IGI, AAF).
#[derive(Clone, Copy)]
pub struct Surfaces<'a> {
    /// RGBA32F world position, w: linear depth (0: background).
    pub position: &'a Handle<Image>,
    /// RGBA16F normal.
    pub normal: &'a Handle<Image>,
    /// Image size.
    pub extent: [u32; 2],
}

impl<'a> From<&'a Receivers> for Surfaces<'a> {
    fn from(r: &'a Receivers) -> Self {
        Self {
            position: &r.position,
            normal: &r.normal,
            extent: r.extent,
        }
    }
}

impl<'a> From<&'a GBuffer> for Surfaces<'a> {
    /// The G-buffer's geometric normals: normal maps do not reject history.
    fn from(g: &'a GBuffer) -> Self {
        Self {
            position: &g.position,
            normal: &g.geometric_normal,
            extent: g.extent,
        }
    }
}

/// Push constants of `shaders/amortise.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ResolvePush {
    /// Size of the resolved image.
    pub extent: [u32; 2],
    /// Full-resolution size (of the motion image).
    pub full_extent: [u32; 2],
    /// 1 + k: the refreshed pixel of every cell; 0: every pixel was shaded.
    pub slice: u32,
    /// 1 when the history holds the previous frame.
    pub has_history: u32,
    /// uints per pixel of the records (variant `records`).
    pub words: u32,
    /// What the change test reads of a record (variant `records`, [`RecordSignal`]): 0 nothing,
    /// 1 packed rgb halves, 2 an rgb sum and its count.
    pub signal: u32,
}

/// Errors of the amortising passes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AmortiseError {
    /// A slice outside `0..=SLICES` (or `0..=REGATHER_SLICE` for a technique's dispatch).
    #[error("amortised slice {0} is out of range")]
    Slice(u32),
    /// The regather slice without the marks of `*_regather_mask` or `*_reproject`.
    #[error("the regather slice needs the marks of the frame's mask or reproject pass")]
    NoMarks,
    /// Records too short for the change test's signal.
    #[error("records of {0} words are too short for their change signal")]
    SignalWords(u32),
}

/// Checks a technique's dispatch of `slice`: at most [`REGATHER_SLICE`], which needs marks.
pub fn check_slice(slice: u32, has_marks: bool) -> Result<(), AmortiseError> {
    match slice {
        REGATHER_SLICE if !has_marks => Err(AmortiseError::NoMarks),
        s if s > REGATHER_SLICE => Err(AmortiseError::Slice(s)),
        _ => Ok(()),
    }
}

/// An amortised technique's temporal images at the resolution it shades: light and
/// (normal, linear depth), keyed by the technique's name.
pub struct ResolveHistory {
    /// The technique's name: the passes' prefix.
    pub name: &'static str,
    /// Resolved light.
    pub light: History<Image>,
    /// Normal and linear depth.
    pub geometry: History<Image>,
}

impl ResolveHistory {
    /// The pair of history images of technique `name` (e.g. `hvl`) for images of `extent`.
    pub fn declare(rg: &mut RenderGraph, name: &'static str, extent: [u32; 2]) -> Self {
        let desc = ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, extent[0], extent[1]);
        Self {
            name,
            light: rg.history_image(&format!("{name} resolved"), desc),
            geometry: rg.history_image(&format!("{name} resolved geometry"), desc),
        }
    }
}

/// Adds `NAME_regather_mask`: marks, in `fresh` (this frame's light at the pixels of `slice`),
/// every other pixel whose history does not show its surface, or whose cell changed by more
/// than [`RESOLVE_CHANGE_LIMIT`] where its refreshed pixel shows another surface (alpha −1; 0
/// elsewhere), for the technique to shade again with [`REGATHER_SLICE`].
pub fn regather_mask(
    rg: &mut RenderGraph,
    surfaces: Surfaces<'_>,
    fresh: &mut Handle<Image>,
    motion: &Handle<Image>,
    history: &ResolveHistory,
    slice: Slice,
) -> Result<(), AmortiseError> {
    let push = resolve_push(surfaces, motion, slice)?;
    rg.compute(
        &format!("{}_regather_mask", history.name),
        &shaders::AMORTISE_COMP_MASK,
    )
    .read("recv_position", surfaces.position)
    .read("recv_normal", surfaces.normal)
    .read("gb_motion", motion)
    .read("history_light", &history.light.previous)
    .read("history_geometry", &history.geometry.previous)
    .write("fresh", fresh)
    .push(&push)
    .dispatch([push.extent[0], push.extent[1], 1]);
    Ok(())
}

/// The push constants of both variants, after checking the slice.
fn resolve_push(
    surfaces: Surfaces<'_>,
    motion: &Handle<Image>,
    slice: Slice,
) -> Result<ResolvePush, AmortiseError> {
    if slice.slice > SLICES {
        return Err(AmortiseError::Slice(slice.slice));
    }
    let full = motion.desc().extent;
    Ok(ResolvePush {
        extent: surfaces.extent,
        full_extent: [full.width, full.height],
        slice: slice.slice,
        has_history: u32::from(slice.has_history),
        words: 0,
        signal: 0,
    })
}

/// Adds `NAME_resolve`: this frame's light `fresh` (at the pixels of the slice and those
/// [`regather_mask`] marked; at every pixel for slice 0, which then passes through) and the
/// reprojected history into the history's current images; returns the resolved light.
pub fn resolve(
    rg: &mut RenderGraph,
    surfaces: Surfaces<'_>,
    fresh: &Handle<Image>,
    motion: &Handle<Image>,
    history: &mut ResolveHistory,
    slice: Slice,
) -> Result<Handle<Image>, AmortiseError> {
    let push = resolve_push(surfaces, motion, slice)?;
    rg.compute(
        &format!("{}_resolve", history.name),
        &shaders::AMORTISE_COMP_RESOLVE,
    )
    .read("recv_position", surfaces.position)
    .read("recv_normal", surfaces.normal)
    .read("fresh", fresh)
    .read("gb_motion", motion)
    .read("history_light", &history.light.previous)
    .read("history_geometry", &history.geometry.previous)
    .write("resolved", &mut history.light.current)
    .write("resolved_geometry", &mut history.geometry.current)
    .push(&push)
    .dispatch([push.extent[0], push.extent[1], 1]);
    Ok(history.light.current)
}

/// A technique amortised by its per-pixel records instead of its light (IGI's gathered VPL set,
/// AAF's sample sums and filter widths: what the technique's filter reads at every pixel every
/// frame): the records and the geometry they were gathered for, as temporal resources keyed by
/// the technique's name. Records are carried over as they are: a record that depends on the
/// view (IGI's glossy term in irradiance mode, the specular part of AAF's sums) keeps the view
/// it was gathered from until its pixel is refreshed, and a carried IGI record keeps the VPL set
/// of the pixel it was gathered at.
pub struct RecordHistory {
    /// The technique's name: the passes' prefix.
    pub name: &'static str,
    /// `words` uints per pixel, row-major.
    pub records: History<Buffer>,
    /// Normal and linear depth.
    pub geometry: History<Image>,
    /// uints per pixel.
    pub words: u32,
    /// What the change test reads of a record.
    pub signal: RecordSignal,
}

/// What `*_reproject`'s change test compares of the records of a cell's refreshed pixel, now
/// against its history, to regather the cell's other pixels the same frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordSignal {
    /// No change test.
    None,
    /// The first two words are an rgb value as packed halves (IGI's first SH coefficient).
    PackedRgb,
    /// The first four words are an rgb sum of samples and their count as floats; the test
    /// compares their mean (AAF's sums: a pixel's samples are drawn with the same seeds every
    /// frame, so a still pixel's mean does not change).
    MeanRgb,
}

impl RecordSignal {
    /// The value of `ResolvePush::signal`.
    fn push(self) -> u32 {
        match self {
            Self::None => 0,
            Self::PackedRgb => 1,
            Self::MeanRgb => 2,
        }
    }

    /// Uints a record needs for the test to read its signal.
    pub fn words(self) -> u32 {
        match self {
            Self::None => 0,
            Self::PackedRgb => 2,
            Self::MeanRgb => 4,
        }
    }
}

impl RecordHistory {
    /// The history of technique `name` (e.g. `igi`) for images of `extent` with `words` uints
    /// per pixel, of which the change test reads `signal`.
    pub fn declare(
        rg: &mut RenderGraph,
        name: &'static str,
        extent: [u32; 2],
        words: u32,
        signal: RecordSignal,
    ) -> Self {
        let bytes = u64::from(extent[0]) * u64::from(extent[1]) * u64::from(words) * 4;
        let desc = ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, extent[0], extent[1]);
        Self {
            name,
            records: rg.history_buffer(&format!("{name} records"), BufferDesc::new(bytes)),
            geometry: rg.history_image(&format!("{name} records geometry"), desc),
            words,
            signal,
        }
    }
}

/// Adds `NAME_reproject` after the refreshed pixels of `slice` gathered their records into
/// `history.records.current`: every other pixel copies its history's records where they show
/// its surface and its block's refreshed records did not change (`history.signal`); returns the
/// marks (RGBA16F, alpha −1) of the others, for the technique to gather with
/// [`REGATHER_SLICE`]. Writes the geometry history.
pub fn reproject_records(
    rg: &mut RenderGraph,
    surfaces: Surfaces<'_>,
    motion: &Handle<Image>,
    history: &mut RecordHistory,
    slice: Slice,
) -> Result<Handle<Image>, AmortiseError> {
    let mut push = resolve_push(surfaces, motion, slice)?;
    push.words = history.words;
    if history.words < history.signal.words() {
        return Err(AmortiseError::SignalWords(history.words));
    }
    push.signal = history.signal.push();
    let [w, h] = surfaces.extent;
    let mut marks = rg.create_image(
        &format!("{}_marks", history.name),
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    rg.compute(
        &format!("{}_reproject", history.name),
        &shaders::AMORTISE_COMP_RECORDS,
    )
    .read("recv_position", surfaces.position)
    .read("recv_normal", surfaces.normal)
    .read("gb_motion", motion)
    .read("history_geometry", &history.geometry.previous)
    .read("history_records", &history.records.previous)
    .write("records", &mut history.records.current)
    .write("fresh", &mut marks)
    .write("resolved_geometry", &mut history.geometry.current)
    .push(&push)
    .dispatch([w, h, 1]);
    Ok(marks)
}
