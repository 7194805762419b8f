//! Command-line interface: one module per subcommand.

mod compare;
mod frame_args;
mod info;
mod lab;
mod merge;
mod profile;
mod progress;
mod reference;
mod render;
mod scene;
mod settings;
mod study;

use clap::{Parser, Subcommand};

/// Errors a subcommand reports to the user (printed as `error: …`, exit status 1).
pub type CliError = Box<dyn std::error::Error>;

/// shine: real-time soft global illumination on Vulkan.
#[derive(Parser, Debug)]
#[command(version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print the Vulkan device shine would use and the features it needs or can use.
    Info(info::InfoArgs),
    /// Render a scene headless to a PNG (tonemapped) or EXR (linear HDR) image.
    Render(render::RenderArgs),
    /// Per-pass GPU times of a scene over many frames.
    Profile(profile::ProfileArgs),
    /// Path-traced reference of a scene (linear EXR): direct, indirect or full radiance.
    Reference(reference::ReferenceArgs),
    /// RMSE, RMSE / mean, energy ratio, PSNR, SSIM and FLIP of an image against a reference
    /// (EXR radiance or PNG as displayed); per-tile grids, a FLIP map and a signed error map.
    Compare(compare::CompareArgs),
    /// Built-in scenes: list them or export one as .glb.
    Scene(scene::SceneArgs),
    /// The GI lab: every technique's error, cost and flicker on the given scenes, the Pareto
    /// front, lab.json/lab.csv and a self-contained index.html.
    Lab(lab::LabArgs),
    /// Joins the parts of a sharded run: a reference's partial sums, a sequence's manifests,
    /// a lab's reports (docs/many-machines.md).
    Merge(merge::MergeArgs),
    /// Every setting: key, default, values, what it changes (docs/settings.md).
    Settings(settings::SettingsArgs),
    /// Quality studies: error against samples per pixel (`study aaf`: paper 004's Fig. 10).
    Study(study::StudyArgs),
}

/// Runs the chosen subcommand.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Info(args) => info::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Profile(args) => profile::run(&args),
        Command::Reference(args) => reference::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Scene(args) => scene::run(&args),
        Command::Lab(args) => lab::run_lab(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Settings(args) => settings::run(&args),
        Command::Study(args) => study::run(&args),
    }
}
