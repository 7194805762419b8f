//! `igi_sets` (`shaders/igi_sets.comp`): the VPL records grouped by interleaved set once a
//! frame, so that `vpl_sh` walks its pixel's set only, in record order (issue 43's mend: every
//! pixel reading every record's identity cost vpl_sh 5.8×, docs/performance.md).

use super::{IgiError, IgiParams, PATTERN, check_vpls};
use crate::graph::{Buffer, BufferDesc, Handle, RenderGraph};
use crate::shaders;

/// Most sets n m of a pattern (`IGI_SETS_MAX` of shaders/include/sample_identity.glsl; igi_sets.comp runs a thread
/// per set).
pub const SETS_MAX: u32 = *PATTERN.end() * *PATTERN.end();

/// Push constants of `shaders/igi_sets.comp` (8 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SetsPush {
    /// VPL count M.
    pub vpl_count: u32,
    /// Sets n m of the pattern.
    pub sets: u32,
}

/// Bytes of the `igi_sets` buffer for `vpl_count` records: [`SETS_MAX`] + 1 first slots, then
/// one index per record.
pub fn sets_bytes(vpl_count: u32) -> u64 {
    4 * (u64::from(SETS_MAX) + 1 + u64::from(vpl_count))
}

/// The VPLs `vpls` (of [`super::vpls`]) and their grouping by interleaved set (of [`sets`]):
/// what [`super::vpl_sh`] reads.
#[derive(Debug, Clone, Copy)]
pub struct VplSets {
    /// The VPL records (layout of [`crate::passes::hvl::Hvl`]).
    pub vpls: Handle<Buffer>,
    /// `igi_sets`: `first[s]` of each set, then the record indices grouped by set.
    pub sets: Handle<Buffer>,
}

/// Adds `igi_sets`: the valid records of `vpls` grouped by interleaved set (the set of their
/// sample identity), in record order within a set; returns both for [`super::vpl_sh`].
pub fn sets(
    rg: &mut RenderGraph,
    vpls: Handle<Buffer>,
    params: &IgiParams,
) -> Result<VplSets, IgiError> {
    params.validate()?;
    check_vpls(&vpls, params)?;
    let mut sets = rg.create_buffer("igi_sets", BufferDesc::new(sets_bytes(params.vpl_count)));
    let push = SetsPush {
        vpl_count: params.vpl_count,
        sets: params.n * params.m,
    };
    rg.compute("igi_sets", &shaders::IGI_SETS_COMP)
        .read("vpls", &vpls)
        .write("sets", &mut sets)
        .push(&push)
        .dispatch([1, 1, 1]);
    Ok(VplSets { vpls, sets })
}
