//! What `shine render` and `shine profile` share: the scene argument and the settings flags.

use super::CliError;
use shine::farm::identity::scene_key;
use shine::gpu::Device;
use shine::lab::budget::{self, BudgetChoice};
use shine::profile::roofline::cache_dir;
use shine::settings::Settings;
use shine_scene::Scene;
use shine_scene::environment::Environment;
use std::path::PathBuf;

/// Settings from a TOML file, then flags over it (one serde struct, file and flags).
#[derive(clap::Args, Debug)]
pub struct SettingsArgs {
    /// Settings file (TOML); flags override it.
    #[arg(long)]
    settings: Option<PathBuf>,
    // The flags are options, so a settings file's value survives a flag not given; their help
    // shows the default of `Settings::default()` (with_default).
    #[arg(long, help = with_default("Image width in pixels", "width"))]
    width: Option<u32>,
    #[arg(long, help = with_default("Image height in pixels", "height"))]
    height: Option<u32>,
    #[arg(long, help = with_default("Scene time in seconds (animations)", "time"))]
    time: Option<f32>,
    #[arg(long, help = with_default(
        "GI techniques: `hvl`, `igi`, `proxy`, `aaf`, `none`, combined with commas (`hvl,proxy`)",
        "gi",
    ))]
    gi: Option<String>,
    #[arg(long, help = with_default(
        "Tonemapping: none, aces, pbr-neutral, agx",
        "output.tonemap",
    ))]
    tonemap: Option<String>,
    #[arg(long, help = with_default(
        "Linear exposure factor of the EXR, and a compensation on top of the automatic exposure \
         of the PNG (`output.auto_exposure`, on by default; `--set output.auto_exposure=false` \
         exposes the PNG by this factor alone)",
        "output.exposure",
    ))]
    exposure: Option<f32>,
    /// Supersampling N (1-4): render at N times the size and box-filter down before
    /// tonemapping (`output.ssaa`; antialiased captures). 0: automatic, 2 while the rendered
    /// frame stays within 1024² pixels (512×512 captures), else 1 (`shine render`'s default
    /// without --settings).
    #[arg(long)]
    ssaa: Option<u32>,
    /// Any setting by its TOML key, e.g. `--set hvl.count=2000` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    overrides: Vec<String>,
    /// Frame budget in ms: the GI configuration with the least error whose measured cost fits,
    /// from `shine lab`'s results for this device and scene at this size (a quick lab of a few
    /// candidates fills them when there are none), over the other settings.
    #[arg(long)]
    budget_ms: Option<f64>,
    #[command(flatten)]
    environment: EnvironmentArgs,
}

/// An environment map replacing the scene's environment (`shine render`, `profile`,
/// `reference`).
#[derive(clap::Args, Debug)]
pub struct EnvironmentArgs {
    /// Equirectangular environment map (.hdr or .exr, linear radiance) lighting the scene
    /// instead of its own environment.
    #[arg(long, value_name = "FILE")]
    environment: Option<PathBuf>,
    /// Multiplier of the --environment map.
    #[arg(long, default_value_t = 1.0)]
    environment_intensity: f32,
}

impl EnvironmentArgs {
    /// Replaces `scene`'s environment by the map, if one was given (dropping the default sun
    /// the loader adds to a scene with no light and no environment).
    pub fn apply(&self, scene: &mut Scene) -> Result<(), CliError> {
        let Some(path) = &self.environment else {
            return Ok(());
        };
        if !(self.environment_intensity.is_finite() && self.environment_intensity >= 0.0) {
            return Err(format!(
                "--environment-intensity must be a finite number ≥ 0, got {}",
                self.environment_intensity
            )
            .into());
        }
        scene.environment = Some(Environment::load_map(path, self.environment_intensity)?);
        // The loader lights a scene with neither lights nor environment by a default sun
        // (node u32::MAX); the map now lights it.
        if scene.lights.iter().any(|l| l.node == u32::MAX) {
            scene.lights.retain(|l| l.node != u32::MAX);
            scene
                .warnings
                .retain(|w| !w.contains("default directional sun"));
        }
        Ok(())
    }
}

/// `what` followed by `[default: V]`, V the setting `key` (a dotted TOML key) of
/// `Settings::default()`: the help of an optional settings flag shows the one default there is.
pub fn with_default(what: &str, key: &str) -> String {
    let defaults = serde_json::to_value(Settings::default()).unwrap_or_default();
    let value = key
        .split('.')
        .try_fold(&defaults, |v, part| v.get(part))
        .map(|v| match v {
            serde_json::Value::String(s) => s.clone(),
            other => other.to_string(),
        });
    match value {
        Some(v) => format!("{what} [default: {v}]"),
        None => what.to_owned(),
    }
}

impl SettingsArgs {
    /// With `--budget-ms`: the configuration chosen for `scene` (given as `argument`) at the
    /// settings' size on `device`, applied to `settings` and printed; `None` without the flag.
    pub fn apply_budget(
        &self,
        settings: &mut Settings,
        scene: &Scene,
        argument: &str,
        device: &Device,
    ) -> Result<Option<BudgetChoice>, CliError> {
        let Some(budget_ms) = self.budget_ms else {
            return Ok(None);
        };
        if !(budget_ms.is_finite() && budget_ms > 0.0) {
            return Err(format!("--budget-ms {budget_ms} must be a positive number of ms").into());
        }
        // The lab's costs are of frames without supersampling: an automatic factor is off.
        if settings.output.ssaa == 0 {
            settings.output.ssaa = 1;
        }
        let extent = [settings.width, settings.height];
        let key = scene_key(argument).unwrap_or_else(|| argument.to_owned());
        let table_path = cache_dir()
            .map(|dir| budget::table_path(&dir, &device.info().name, &device.info().driver));
        let table = match &table_path {
            Some(path) => budget::load_table(path)?,
            None => budget::BudgetTable::default(),
        };
        let choice = match budget::choose(&table, Some(&key), extent, budget_ms) {
            Some(choice) => choice,
            None => {
                eprintln!(
                    "budget: no lab results for {argument} at {}×{} on {}: a quick lab of {} candidates …",
                    extent[0],
                    extent[1],
                    device.info().name,
                    budget::candidates().len()
                );
                let (entries, seconds) =
                    budget::fill(device, scene, &key, extent, table_path.as_deref())?;
                eprintln!("budget: the quick lab took {seconds:.1} s");
                let refs: Vec<&budget::BudgetEntry> = entries.iter().collect();
                budget::pick(&refs, budget_ms).ok_or("budget: no candidate could be measured")?
            }
        };
        for (k, v) in &choice.config.set {
            settings.set(k, v)?;
        }
        settings.validate()?;
        eprintln!("{}", choice.describe());
        Ok(Some(choice))
    }

    /// The file's settings (or the defaults) with every flag applied, validated.
    pub fn resolve(&self) -> Result<Settings, CliError> {
        self.resolve_from(Settings::default())
    }

    /// As [`SettingsArgs::resolve`] for a capture: without a settings file the defaults
    /// supersample automatically (`output.ssaa = 0`, the best antialiasing that fits the
    /// time; docs/quality.md).
    pub fn resolve_capture(&self) -> Result<Settings, CliError> {
        let mut defaults = Settings::default();
        defaults.output.ssaa = 0;
        self.resolve_from(defaults)
    }

    /// The file's settings (or `defaults`) with every flag applied, validated.
    fn resolve_from(&self, defaults: Settings) -> Result<Settings, CliError> {
        let mut settings = match &self.settings {
            Some(path) => Settings::load(path)?,
            None => defaults,
        };
        let flags = [
            ("width", self.width.map(|v| v.to_string())),
            ("height", self.height.map(|v| v.to_string())),
            ("time", self.time.map(|v| v.to_string())),
            ("gi", self.gi.clone()),
            ("output.tonemap", self.tonemap.clone()),
            ("output.exposure", self.exposure.map(|v| v.to_string())),
            ("output.ssaa", self.ssaa.map(|v| v.to_string())),
        ];
        for (key, value) in flags {
            if let Some(value) = value {
                settings.set(key, &value)?;
            }
        }
        for assignment in &self.overrides {
            let (key, value) = assignment
                .split_once('=')
                .ok_or_else(|| format!("--set expects KEY=VALUE, got `{assignment}`"))?;
            settings.set(key.trim(), value.trim())?;
        }
        settings.validate()?;
        Ok(settings)
    }
}

impl SettingsArgs {
    /// The environment map flags (part of what a run is).
    pub fn environment(&self) -> &EnvironmentArgs {
        &self.environment
    }

    /// Loads the scene `argument` with the `--environment` map applied.
    pub fn load_scene(&self, argument: &str) -> Result<Scene, CliError> {
        load_scene(argument, &self.environment)
    }
}

/// Loads `builtin:NAME` or a .gltf/.glb path, printing the loader's warnings, and applies
/// `environment`.
pub fn load_scene(argument: &str, environment: &EnvironmentArgs) -> Result<Scene, CliError> {
    let mut scene = match argument.strip_prefix("builtin:") {
        Some(name) => Scene::builtin(name)?,
        None => shine_scene::load(argument)?,
    };
    environment.apply(&mut scene)?;
    for warning in &scene.warnings {
        eprintln!("warning: {warning}");
    }
    Ok(scene)
}
