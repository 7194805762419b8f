//! Named choices: enums whose variant names are the single source for settings files, the
//! command line and the error that lists the known names. Each module that owns a choice
//! (`passes::hvl::RadiusHeuristic`, `capture::tonemap::Tonemap`, …) declares it with
//! `named_choice!`; the settings only use them.

/// A name that matches no variant of a named choice.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} `{name}`: expected one of {known}")]
pub struct UnknownChoice {
    /// What was being named (`tonemap operator`).
    pub what: &'static str,
    /// The name given.
    pub name: String,
    /// The known names, comma-separated.
    pub known: String,
}

/// Defines an enum of named choices whose names are the single source for TOML, the CLI
/// ([`FromStr`](std::str::FromStr), [`std::fmt::Display`]) and the error listing the known names.
macro_rules! named_choice {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident ($what:literal) {
            $( $(#[$vmeta:meta])* $variant:ident = $text:literal, )+
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        $vis enum $name {
            $( $(#[$vmeta])* $variant, )+
        }

        impl $name {
            /// Every choice, in documentation order.
            pub const ALL: &'static [$name] = &[$($name::$variant),+];

            /// The name used in settings files and on the command line.
            pub fn name(self) -> &'static str {
                match self {
                    $( $name::$variant => $text, )+
                }
            }
        }

        impl $crate::declare::SettingValue for $name {
            fn domain(&self) -> $crate::declare::Domain {
                $crate::declare::Domain::Choice(Self::ALL.iter().map(|c| c.name()).collect())
            }
        }

        impl std::str::FromStr for $name {
            type Err = $crate::choice::UnknownChoice;

            fn from_str(s: &str) -> Result<Self, $crate::choice::UnknownChoice> {
                Self::ALL
                    .iter()
                    .copied()
                    .find(|c| c.name() == s)
                    .ok_or_else(|| $crate::choice::UnknownChoice {
                        what: $what,
                        name: s.to_owned(),
                        known: Self::ALL.iter().map(|c| c.name()).collect::<Vec<_>>().join(", "),
                    })
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }

        impl<'de> serde::Deserialize<'de> for $name {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = <String as serde::Deserialize>::deserialize(d)?;
                text.parse().map_err(serde::de::Error::custom)
            }
        }
    };
}
pub(crate) use named_choice;
