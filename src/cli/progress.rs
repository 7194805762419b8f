//! Progress bars of the long subcommands (indicatif draws them on stderr, and not at all when
//! stderr is not a terminal).

/// A bar of `len` steps drawn with the indicatif `template` (the default bar if the template
/// does not parse).
pub fn bar(len: u64, template: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template(template)
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}
