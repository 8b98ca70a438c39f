//! [`choice!`]: enums whose values users name in text (the command line, Python, JSON), with
//! one spelling per value, parsed by `FromStr` (an error lists the allowed names), printed by
//! `Display`, and offered to clap as possible values when the `cli` feature is on.

/// Declares a `Copy` enum of named choices:
///
/// ```text
/// choice! {
///     /// What the design minimises.
///     pub enum Criterion ("criterion") {
///         /// log10 cond(Phi).
///         Cond = "cond",
///         LogDet = "logdet" | "log_det",
///     }
/// }
/// ```
///
/// The string after the name is the argument the choice is given as (named in errors); the
/// first string of each value is its name, the others are accepted aliases.
macro_rules! choice {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident ($argument:literal) {
            $(
                $(#[$vmeta:meta])*
                $variant:ident = $text:literal $(| $alias:literal)*
            ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        $vis enum $name {
            $( $(#[$vmeta])* $variant ),+
        }

        impl $name {
            /// Every value, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$variant),+];

            /// The value's name, as parsed by `FromStr` and printed by `Display`.
            pub fn name(self) -> &'static str {
                match self {
                    $($name::$variant => $text),+
                }
            }
        }

        impl std::str::FromStr for $name {
            type Err = $crate::error::Error;

            fn from_str(text: &str) -> $crate::error::Result<Self> {
                match text {
                    $($text $(| $alias)* => Ok($name::$variant),)+
                    other => Err($crate::error::Error::invalid(
                        $argument,
                        format!(
                            "'{other}'; expected one of {}",
                            [$($text),+].join(", ")
                        ),
                    )),
                }
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        #[cfg(feature = "cli")]
        impl clap::ValueEnum for $name {
            fn value_variants<'a>() -> &'a [Self] {
                Self::ALL
            }

            fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
                let value = clap::builder::PossibleValue::new(self.name());
                Some(match self {
                    $($name::$variant => value $(.alias($alias))*),+
                })
            }
        }
    };
}
pub(crate) use choice;
