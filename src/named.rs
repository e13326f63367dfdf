//! The names of the settings' values: one table per enum gives its `FromStr`, `Display`,
//! `name()` and `NAMES` (the spelling of the command line, the Python keywords, the JSON
//! report and the ParaView properties), so that no front end spells a value on its own.

/// Implements `NAMES`, `name()`, `FromStr` (a usage error listing the names) and `Display`
/// for a `Copy` enum from its table of `(variant, "name")`.
macro_rules! named_enum {
    ($ty:ty, $what:literal, [$(($variant:path, $name:literal)),+ $(,)?]) => {
        impl $ty {
            /// Every value's name, as the settings' text spells it.
            pub const NAMES: &'static [&'static str] = &[$($name),+];

            /// This value's name.
            pub fn name(self) -> &'static str {
                match self {
                    $($variant => $name),+
                }
            }
        }

        impl std::str::FromStr for $ty {
            type Err = crate::error::Error;

            fn from_str(text: &str) -> crate::error::Result<Self> {
                match text.trim() {
                    $($name => Ok($variant),)+
                    other => Err(crate::error::Error::Usage(format!(
                        "{} `{other}` is not one of {}",
                        $what,
                        Self::NAMES.join(", ")
                    ))),
                }
            }
        }

        impl std::fmt::Display for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}
