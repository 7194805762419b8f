//! `shine settings`: every setting as its declaration gives it (key, default, values, what it
//! changes, doc), as the markdown table of docs/settings.md or as JSON for scripts.

use super::CliError;
use shine::Settings;
use shine::declare::{Section, specs_json};

/// Arguments of `shine settings`.
#[derive(clap::Args, Debug)]
pub struct SettingsArgs {
    /// `markdown` (the page docs/settings.md) or `json`.
    #[arg(long, default_value = "markdown")]
    format: String,
}

/// Prints every setting.
pub fn run(args: &SettingsArgs) -> Result<(), CliError> {
    let specs = Settings::specs();
    match args.format.as_str() {
        "markdown" => print!("{}", shine::settings::settings_page()),
        "json" => println!("{}", serde_json::to_string_pretty(&specs_json(&specs))?),
        other => return Err(format!("unknown format `{other}`: expected markdown or json").into()),
    }
    Ok(())
}
