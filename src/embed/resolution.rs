//! A GI context's internal resolution: the share of the display size its indirect light is
//! computed at before the joint bilateral upsample to the display (docs/embedding.md
//! "Internal resolution").

use crate::frame::RenderError;

/// The internal resolutions a context offers, in per cent of the display's width and height
/// (the FidelityFX-style quality steps: native, 75 %, 50 %, 25 %).
pub const INTERNAL_PERCENTS: [u32; 4] = [100, 75, 50, 25];

/// The size a [`GiContext`](super::GiContext) computes its light at, as a share of the
/// display's width and height ([`INTERNAL_PERCENTS`]). Below 100 % the host's G-buffer is
/// point-sampled to the internal size (each internal pixel keeps one whole host sample), every
/// technique and the history run there, and the outputs are upsampled joint-bilaterally
/// (paper 002 eq. 11), guided by the display-size depth and normals, so edges stay the
/// host's. Receiver-resolution techniques (HVL, proxies) still divide by `receiver_scale` on
/// top.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum InternalResolution {
    /// The display size: no upsample.
    #[default]
    Full,
    /// 75 % of each side (56 % of the pixels).
    ThreeQuarters,
    /// 50 % of each side (a quarter of the pixels).
    Half,
    /// 25 % of each side (1/16 of the pixels).
    Quarter,
}

impl InternalResolution {
    /// Every choice, largest first (in the order of [`INTERNAL_PERCENTS`]).
    pub const ALL: [Self; 4] = [Self::Full, Self::ThreeQuarters, Self::Half, Self::Quarter];

    /// The share of each side, in per cent.
    pub fn percent(self) -> u32 {
        INTERNAL_PERCENTS[self as usize]
    }

    /// The choice of `percent`, or an error naming the ones there are.
    pub fn from_percent(percent: u32) -> Result<Self, RenderError> {
        Self::ALL
            .into_iter()
            .find(|r| r.percent() == percent)
            .ok_or_else(|| {
                RenderError::Invalid(format!(
                    "GI context: internal resolution {percent} % is not offered: use one of \
                     {INTERNAL_PERCENTS:?}"
                ))
            })
    }

    /// The internal size for `display`: each side `ceil(side · percent / 100)`, at least 1.
    pub fn extent(self, display: [u32; 2]) -> [u32; 2] {
        display.map(|side| {
            let scaled = u64::from(side) * u64::from(self.percent());
            (scaled.div_ceil(100) as u32).max(1)
        })
    }
}
