//! Settings declared once (issue 45): what `#[derive(Settings)]` (crate
//! `shine-settings-derive`) generates code against.
//!
//! A setting is one field of a serde section struct with one `#[setting(default = …, range =
//! …, affects = …)]` attribute and a doc comment, declared by the pass or technique that uses
//! it. From that declaration come the TOML file and `--set` (serde),
//! [`Settings::validate`](crate::settings::Settings::validate) and the passes' own parameter
//! checks ([`Section::check_in`]), the list of every setting with its domain and default
//! ([`Section::specs`]: the lab's parameter space) and the table in `docs/settings.md`
//! ([`markdown_table`]). This module sits beside `choice.rs` at the bottom of the crate:
//! passes and settings both use it.

use std::fmt;
use std::ops::RangeInclusive;

use serde::Serialize;

pub use shine_settings_derive::Settings;

/// A setting outside the values it accepts: the dotted key, the value and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("setting `{field}` = {value} is out of range: allowed {allowed}")]
pub struct OutOfRange {
    /// Dotted key of the setting, as written in the TOML file (`hvl.count`).
    pub field: String,
    /// The rejected value, as given.
    pub value: String,
    /// The allowed values (`64..=10000`, `[1, 2, 4]`).
    pub allowed: String,
}

/// What a setting changes: the lab varies those that change cost or quality.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Affects {
    /// Time only (the same image, faster or slower).
    Cost,
    /// The image only (at the same cost).
    Quality,
    /// Both the time and the image.
    Both,
    /// How the frame is written (size, tonemap, which part): neither the GI's cost nor its
    /// error against the truth.
    Output,
}

impl Affects {
    /// The name used in tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Affects::Cost => "cost",
            Affects::Quality => "quality",
            Affects::Both => "both",
            Affects::Output => "output",
        }
    }
}

/// The values a setting accepts.
#[derive(Debug, Clone, PartialEq)]
pub enum Domain {
    /// `true` or `false`.
    Bool,
    /// An integer in `min..=max`.
    Int {
        /// The least value.
        min: i64,
        /// The greatest value.
        max: i64,
    },
    /// A finite number in `min..=max`.
    Float {
        /// The least value.
        min: f64,
        /// The greatest value.
        max: f64,
    },
    /// One of a few integers.
    OneOf(Vec<i64>),
    /// Zero (an automatic choice), or a value of the inner domain.
    ZeroOr(Box<Domain>),
    /// One of named choices.
    Choice(Vec<&'static str>),
    /// A text the setting parses itself (the `gi` list).
    Text,
}

impl Domain {
    /// The domain of a range constant.
    pub fn range<T: RangeValue>(range: &RangeInclusive<T>) -> Self {
        T::domain(range)
    }

    /// The domain of a list of allowed integers.
    pub fn one_of<T: Copy + Into<i64>>(values: &[T]) -> Self {
        Domain::OneOf(values.iter().map(|&v| v.into()).collect())
    }

    /// Zero, or a value of `range`.
    pub fn zero_or<T: RangeValue>(range: &RangeInclusive<T>) -> Self {
        Domain::ZeroOr(Box::new(T::domain(range)))
    }
}

impl ParamSpec {
    /// The values the lab tries by default: the ends and the middle of the lab span (the
    /// domain unless the declaration narrows it), every value of a short list, both booleans,
    /// every named choice; never the default itself (the technique's default configuration
    /// has it). Values as `--set` takes them.
    pub fn lab_values(&self) -> Vec<String> {
        let domain = self.lab.as_ref().unwrap_or(&self.domain);
        let default = self.default.to_string();
        domain
            .samples()
            .into_iter()
            .filter(|v| v.trim_matches('"') != default.trim_matches('"'))
            .collect()
    }
}

impl Domain {
    /// Ends and middle of a range, every listed value, both booleans, every choice.
    fn samples(&self) -> Vec<String> {
        let mut out = match self {
            Domain::Bool => vec!["true".to_owned(), "false".to_owned()],
            Domain::Int { min, max } => {
                vec![
                    min.to_string(),
                    ((min + max) / 2).to_string(),
                    max.to_string(),
                ]
            }
            Domain::Float { min, max } => [*min, 0.5 * (min + max), *max]
                .iter()
                .map(|v| format!("{:?}", *v as f32))
                .collect(),
            Domain::OneOf(values) => values.iter().map(i64::to_string).collect(),
            Domain::ZeroOr(inner) => {
                let mut v = vec!["0".to_owned()];
                v.extend(inner.samples());
                v
            }
            Domain::Choice(names) => names.iter().map(|n| (*n).to_owned()).collect(),
            Domain::Text => Vec::new(),
        };
        out.dedup();
        out
    }
}

impl fmt::Display for Domain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Domain::Bool => f.write_str("true, false"),
            Domain::Int { min, max } => write!(f, "{min}..={max}"),
            Domain::Float { min, max } => write!(f, "{min:?}..={max:?}"),
            Domain::OneOf(values) => {
                let names: Vec<String> = values.iter().map(i64::to_string).collect();
                f.write_str(&names.join(", "))
            }
            Domain::ZeroOr(inner) => write!(f, "0 or {inner}"),
            Domain::Choice(names) => f.write_str(&names.join(", ")),
            Domain::Text => f.write_str("text"),
        }
    }
}

/// A numeric type whose range constants give a [`Domain`].
pub trait RangeValue: PartialOrd + Copy + fmt::Debug {
    /// The domain of `range`.
    fn domain(range: &RangeInclusive<Self>) -> Domain;
    /// Whether the value is zero (for `zero_or`).
    fn is_zero(self) -> bool;
}

impl RangeValue for u32 {
    fn domain(range: &RangeInclusive<Self>) -> Domain {
        Domain::Int {
            min: i64::from(*range.start()),
            max: i64::from(*range.end()),
        }
    }
    fn is_zero(self) -> bool {
        self == 0
    }
}

impl RangeValue for f32 {
    fn domain(range: &RangeInclusive<Self>) -> Domain {
        Domain::Float {
            min: shortest(*range.start()),
            max: shortest(*range.end()),
        }
    }
    fn is_zero(self) -> bool {
        self == 0.0
    }
}

/// The domain of a setting declared without a range: its type's values.
pub trait SettingValue {
    /// Every value the type can take.
    fn domain(&self) -> Domain;
}

impl SettingValue for bool {
    fn domain(&self) -> Domain {
        Domain::Bool
    }
}

/// One setting, as declared: the lab's parameter space and the docs' table are lists of these.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    /// Dotted key, as in a TOML file or `--set` (`hvl.count`).
    pub key: String,
    /// The field's doc comment on one line.
    pub doc: &'static str,
    /// The values it accepts.
    pub domain: Domain,
    /// The span the lab explores when narrower than the domain (`#[setting(lab = …)]`).
    pub lab: Option<Domain>,
    /// Its default, as TOML writes it.
    pub default: toml::Value,
    /// What it changes.
    pub affects: Affects,
}

/// A struct of settings (`#[derive(Settings)]`): a TOML section or the whole file.
pub trait Section: Default {
    /// Appends every setting of the section, keys prefixed by `prefix` (`"hvl."`).
    fn specs_into(prefix: &str, out: &mut Vec<ParamSpec>);

    /// Checks every value against its declared domain and the section's relations; the error
    /// names the first offending key, prefixed by `prefix`.
    fn check_in(&self, prefix: &str) -> Result<(), OutOfRange>;

    /// Every setting of the section, in declaration order.
    fn specs() -> Vec<ParamSpec> {
        let mut out = Vec::new();
        Self::specs_into("", &mut out);
        out
    }
}

/// The f64 nearest the shortest decimal that reads back as `value` (`0.1f32` → `0.1`, not
/// `0.10000000149011612`): how a person wrote the constant.
fn shortest(value: f32) -> f64 {
    format!("{value:?}").parse().unwrap_or(f64::from(value))
}

/// A default as TOML writes it (a value that does not serialise becomes its debug text); an
/// f32's in its shortest decimal.
pub fn to_value<T: Serialize + fmt::Debug>(value: &T) -> toml::Value {
    match toml::Value::try_from(value) {
        Ok(toml::Value::Float(x)) if f64::from(x as f32) == x => {
            toml::Value::Float(shortest(x as f32))
        }
        Ok(other) => other,
        Err(_) => toml::Value::String(format!("{value:?}")),
    }
}

/// The out-of-range error of `prefix``key`.
fn out_of_range(prefix: &str, key: &str, value: String, allowed: String) -> OutOfRange {
    OutOfRange {
        field: format!("{prefix}{key}"),
        value,
        allowed,
    }
}

/// Rejects `value` outside `range` (NaN included). Values print with `Debug` so that floats
/// keep their decimal point (`1.0..=2.0`).
pub fn check_range<T: PartialOrd + fmt::Debug>(
    prefix: &str,
    key: &str,
    value: &T,
    range: &RangeInclusive<T>,
) -> Result<(), OutOfRange> {
    if range.contains(value) {
        return Ok(());
    }
    Err(out_of_range(
        prefix,
        key,
        format!("{value:?}"),
        format!("{:?}..={:?}", range.start(), range.end()),
    ))
}

/// Rejects a value that is not one of `values`.
pub fn check_one_of<T: PartialEq + fmt::Debug>(
    prefix: &str,
    key: &str,
    value: T,
    values: &[T],
) -> Result<(), OutOfRange> {
    if values.contains(&value) {
        return Ok(());
    }
    Err(out_of_range(
        prefix,
        key,
        format!("{value:?}"),
        format!("{values:?}"),
    ))
}

/// Accepts zero or a value of `range`.
pub fn check_zero_or<T: RangeValue>(
    prefix: &str,
    key: &str,
    value: &T,
    range: &RangeInclusive<T>,
) -> Result<(), OutOfRange> {
    if value.is_zero() {
        return Ok(());
    }
    check_range(prefix, key, value, range).map_err(|_| {
        out_of_range(
            prefix,
            key,
            format!("{value:?}"),
            format!("0 or {:?}..={:?}", range.start(), range.end()),
        )
    })
}

/// The settings as a markdown table (key, default, values, what it changes, doc): the body
/// of `docs/settings.md`, which a test keeps equal to it.
pub fn markdown_table(specs: &[ParamSpec]) -> String {
    let mut out =
        String::from("| key | default | values | changes | what it is |\n|---|---|---|---|---|\n");
    for s in specs {
        let default = match &s.default {
            toml::Value::String(text) => format!("`\"{text}\"`"),
            other => format!("`{other}`"),
        };
        out.push_str(&format!(
            "| `{}` | {} | {} | {} | {} |\n",
            s.key,
            default,
            s.domain.to_string().replace('|', "\\|"),
            s.affects.name(),
            plain_doc(s.doc).replace('|', "\\|"),
        ));
    }
    out
}

/// A doc comment without rustdoc's links: "[`x`](path)" and "[`x`]" become "`x`".
fn plain_doc(doc: &str) -> String {
    let mut out = String::with_capacity(doc.len());
    let mut rest = doc;
    while let Some(open) = rest.find("[`") {
        let Some(close) = rest[open..].find("`]").map(|c| open + c) else {
            break;
        };
        out.push_str(&rest[..open]);
        out.push_str(&rest[open + 1..close + 1]);
        rest = &rest[close + 2..];
        if rest.starts_with('(')
            && let Some(end) = rest.find(')')
        {
            rest = &rest[end + 1..];
        }
    }
    out.push_str(rest);
    out
}

/// The settings as JSON: one object per setting (key, default, values, changes, doc), with
/// the domain's bounds as numbers where it has them.
pub fn specs_json(specs: &[ParamSpec]) -> serde_json::Value {
    let domain = |d: &Domain| match d {
        Domain::Int { min, max } => serde_json::json!({ "int": [min, max] }),
        Domain::Float { min, max } => serde_json::json!({ "float": [min, max] }),
        other => serde_json::json!(other.to_string()),
    };
    specs
        .iter()
        .map(|s| {
            serde_json::json!({
                "key": s.key,
                "default": serde_json::to_value(&s.default).unwrap_or_default(),
                "values": domain(&s.domain),
                "changes": s.affects.name(),
                "doc": plain_doc(s.doc),
            })
        })
        .collect()
}
