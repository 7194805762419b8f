//! `shine scene`: the built-in procedural scenes (written to assets/ with `export`).

use super::CliError;
use std::path::PathBuf;

/// Arguments of `shine scene`.
#[derive(clap::Args, Debug)]
pub struct SceneArgs {
    #[command(subcommand)]
    command: SceneCommand,
}

#[derive(clap::Subcommand, Debug)]
enum SceneCommand {
    /// List the built-in scenes.
    List,
    /// Write a built-in scene as a .glb file (atomically: a temporary file, then a rename).
    Export {
        /// Built-in scene name (see `shine scene list`).
        name: String,
        /// Output .glb path.
        output: PathBuf,
    },
}

/// Runs `shine scene …`.
pub fn run(args: &SceneArgs) -> Result<(), CliError> {
    match &args.command {
        SceneCommand::List => {
            for name in shine_scene::builtin::names() {
                println!("{name}");
            }
            Ok(())
        }
        SceneCommand::Export { name, output } => {
            shine_scene::builtin::export(name, output)?;
            println!("wrote {}", output.display());
            Ok(())
        }
    }
}
