//! A GI context's frame budget (`GiContextDesc::budget_ms`): the configuration with the least
//! error whose cost fits, from `shine lab`'s stored results for this device, or from a quick
//! lab of a few candidates on the context's first scene (src/lab/budget.rs).

use crate::farm::identity::fnv1a;
use crate::frame::RenderError;
use crate::lab::LabError;
use crate::lab::budget::{self, BudgetChoice, BudgetEntry};
use crate::profile::roofline::cache_dir;
use crate::settings::Settings;
use shine_gpu::Device;
use shine_scene::Scene;

/// The pick for `ms` at the `internal` size from the stored lab results of `device` (every
/// scene's); `None` without results that fit.
pub(super) fn from_results(
    device: &Device,
    internal: [u32; 2],
    ms: f64,
) -> Result<Option<BudgetChoice>, RenderError> {
    let table = match cache_dir() {
        Some(dir) => budget::load_table(&budget::table_path(
            &dir,
            &device.info().name,
            &device.info().driver,
        ))
        .map_err(lab_error)?,
        None => budget::BudgetTable::default(),
    };
    Ok(budget::choose(&table, None, internal, ms))
}

/// The pick for `ms` at the `internal` size from a quick lab of a few candidates on `scene`
/// posed at `t` (takes seconds; its results are stored under the scene's shape for next time).
pub(super) fn from_quick_lab(
    device: &Device,
    scene: &Scene,
    t: f32,
    internal: [u32; 2],
    ms: f64,
) -> Result<BudgetChoice, RenderError> {
    let path =
        cache_dir().map(|dir| budget::table_path(&dir, &device.info().name, &device.info().driver));
    let shape = format!(
        "{:?} {} {} {}",
        scene.pose_bounds(&scene.pose_at(t)),
        scene.nodes.len(),
        scene.meshes.len(),
        scene.lights.len()
    );
    let key = format!("host-{:016x}", fnv1a(shape.as_bytes()));
    let (entries, _) =
        budget::fill(device, scene, &key, internal, path.as_deref()).map_err(lab_error)?;
    let refs: Vec<&BudgetEntry> = entries.iter().collect();
    budget::pick(&refs, ms).ok_or_else(|| {
        RenderError::Invalid("GI context: no budget candidate could be measured".into())
    })
}

/// `choice`'s settings over `settings`, validated.
pub(super) fn apply(settings: &mut Settings, choice: &BudgetChoice) -> Result<(), RenderError> {
    for (key, value) in &choice.config.set {
        settings
            .set(key, value)
            .map_err(|e| RenderError::Invalid(format!("GI context budget: {e}")))?;
    }
    settings.validate()?;
    Ok(())
}

/// A lab error as the context reports it.
fn lab_error(e: LabError) -> RenderError {
    RenderError::Invalid(format!("GI context budget: {e}"))
}
