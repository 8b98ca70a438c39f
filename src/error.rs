//! The one error type of the library. Every variant carries the context a user needs to find
//! the problem: the file, line, element, joint, argument or index involved.

use std::fmt;

/// Where a URDF element stands: the source (a file path or `<string>`) and, when known, the
/// 1-based line of the element.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    pub source: String,
    pub line: Option<u32>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}", self.source, line),
            None => write!(f, "{}", self.source),
        }
    }
}

/// Which limit a planned trajectory breaks, with the limit's values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Limit {
    /// A position outside `[lower, upper]` (rad or m).
    Position { lower: f64, upper: f64 },
    /// A speed above the limit (rad/s or m/s).
    Velocity(f64),
    /// An acceleration above the limit (rad/s^2 or m/s^2).
    Acceleration(f64),
}

/// A planned trajectory that breaks a joint limit: the payload of [`Error::LimitViolation`].
#[derive(Debug, Clone, PartialEq)]
pub struct LimitViolation {
    /// What was being planned, e.g. `experiment 'D' of the plan`.
    pub context: String,
    pub joint: String,
    /// Time from the start of the trajectory (s).
    pub time: f64,
    /// The position, velocity or acceleration found (SI units of the joint).
    pub value: f64,
    pub limit: Limit,
    /// `rad` or `m` for the joint's kind (the rate suffixes are added).
    pub unit: &'static str,
    /// A suggestion, starting with "; " (or empty).
    pub hint: String,
}

impl fmt::Display for LimitViolation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let LimitViolation {
            context,
            joint,
            time,
            value,
            unit,
            hint,
            ..
        } = self;
        write!(f, "{context}: joint '{joint}' at t = {time:.4} s: ")?;
        // six decimals, as a controller's units show them; past a million, an exponent
        let x = |v: f64| {
            if v.abs() < 1e6 {
                format!("{v:.6}")
            } else {
                format!("{v:e}")
            }
        };
        match self.limit {
            Limit::Position { lower, upper } => {
                let by = (lower - value).max(value - upper);
                write!(
                    f,
                    "position {} {unit} is outside [{}, {}] {unit} by {} {unit}",
                    x(*value),
                    x(lower),
                    x(upper),
                    x(by)
                )?
            }
            Limit::Velocity(l) => write!(
                f,
                "velocity {} {unit}/s is outside the limit +-{} {unit}/s by {} {unit}/s",
                x(*value),
                x(l),
                x(value.abs() - l)
            )?,
            Limit::Acceleration(l) => write!(
                f,
                "acceleration {} {unit}/s^2 is outside the limit +-{} {unit}/s^2 by {} {unit}/s^2",
                x(*value),
                x(l),
                x(value.abs() - l)
            )?,
        }
        write!(f, "{hint}")
    }
}

/// What kind of problem an [`Error`] is, for callers that handle errors by kind (the Python
/// exception classes follow it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorKind {
    /// A URDF or robot model that cannot be built (Python `ModelError`).
    Model,
    /// An argument, a recording or a document that cannot be used (Python `InputError`, also a
    /// `ValueError`).
    Input,
    /// A numerical failure (Python `NumericalError`, also an `ArithmeticError`).
    Numerical,
    /// A file that cannot be read or written (Python `FileError`, also an `OSError`).
    File,
    /// Long work stopped by the user (Ctrl-C; Python `KeyboardInterrupt`).
    Interrupted,
    /// A bug of this library caught at its boundary (Python `InternalError`).
    Internal,
}

/// All errors of perturbid_rs.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },

    /// The URDF is not well-formed XML or does not follow the URDF schema.
    #[error("{source_name}: not a valid URDF: {message}")]
    UrdfSyntax {
        source_name: String,
        message: String,
    },

    /// A joint type the library does not model (floating, planar, spherical).
    #[error("{location}: joint '{joint}' is of type {kind}; only revolute, continuous, prismatic and fixed joints are supported (a floating base is not modelled)")]
    UnsupportedJoint {
        location: Box<Location>,
        joint: String,
        kind: String,
    },

    /// The kinematic graph does not have exactly one root link.
    #[error("{source_name}: the URDF must have exactly one root link (a link that is no joint's child), found {}: {}", roots.len(), roots.join(", "))]
    RootCount {
        source_name: String,
        roots: Vec<String>,
    },

    /// Links that cannot be reached from the root: the joints form a cycle.
    #[error("{source_name}: the joints form a cycle through link(s) {}", links.join(", "))]
    Cycle {
        source_name: String,
        links: Vec<String>,
    },

    /// A link is the child of two joints.
    #[error(
        "{location}: link '{link}' is the child of joint '{first}' and again of joint '{second}'"
    )]
    DuplicateChild {
        location: Box<Location>,
        link: String,
        first: String,
        second: String,
    },

    /// Two elements share a name.
    #[error("{location}: {element} name '{name}' is used twice")]
    DuplicateName {
        location: Box<Location>,
        element: &'static str,
        name: String,
    },

    /// A joint names a link that does not exist.
    #[error("{location}: joint '{joint}' names {role} link '{link}', which does not exist")]
    UnknownLink {
        location: Box<Location>,
        joint: String,
        role: &'static str,
        link: String,
    },

    /// A joint name given by the user or by a mimic tag does not exist or cannot be used there.
    #[error("{context}: {message}")]
    JointReference { context: String, message: String },

    /// A link inertia that no rigid body can have.
    #[error("{location}: link '{link}' has a physically invalid inertia: {reason}")]
    InvalidInertia {
        location: Box<Location>,
        link: String,
        reason: String,
    },

    /// A moving joint whose subtree carries no mass and no inertia: M(q) would be singular.
    #[error("{location}: joint '{joint}' moves nothing: the links behind it have no mass and no inertia, so the mass matrix would be singular")]
    MasslessSubtree {
        location: Box<Location>,
        joint: String,
    },

    /// A joint axis of zero length or with non-finite components.
    #[error(
        "{location}: joint '{joint}' has axis {axis:?}, which is not a finite non-zero vector"
    )]
    InvalidAxis {
        location: Box<Location>,
        joint: String,
        axis: [f64; 3],
    },

    /// A revolute or prismatic joint without a `<limit>` element (required by the URDF spec).
    #[error("{location}: {kind} joint '{joint}' has no <limit> element (the URDF specification requires one; use type=\"continuous\" for an unlimited revolute joint)")]
    MissingLimit {
        location: Box<Location>,
        joint: String,
        kind: &'static str,
    },

    /// A number in the URDF that is NaN or infinite where a finite value is required.
    #[error("{location}: {element} '{name}': {field} is {}, expected a finite number below 1e12 in size", shown(*.value))]
    NonFiniteUrdf {
        location: Box<Location>,
        element: &'static str,
        name: String,
        field: &'static str,
        value: f64,
    },

    /// An argument of the wrong length or shape.
    #[error("{argument}: expected {expected}, got {got}")]
    Shape {
        argument: String,
        expected: String,
        got: String,
    },

    /// An argument holding NaN or infinity.
    #[error("{argument}: entry {index} is {value}, expected a finite number")]
    NonFiniteInput {
        argument: String,
        index: usize,
        value: f64,
    },

    /// An argument outside its admissible range (not a shape problem).
    #[error("{argument}: {message}")]
    InvalidArgument { argument: String, message: String },

    /// A numerical failure, e.g. a mass matrix that is not positive definite.
    #[error("{operation}: {message}")]
    Numerical { operation: String, message: String },

    /// A planned trajectory breaks a joint limit (position, velocity or acceleration).
    #[error("{0}")]
    LimitViolation(Box<LimitViolation>),

    /// A least-squares design matrix without full column rank: the data do not excite some
    /// directions.
    #[error("{context}: the design matrix ({rows} x {cols}) has rank {rank} < {cols}; not excited: {missing}")]
    RankDeficient {
        context: String,
        rows: usize,
        cols: usize,
        rank: usize,
        /// The missing directions in terms of the named columns.
        missing: String,
    },

    /// A recording that cannot be used: too short, unordered time, too few samples, ...
    #[error("{recording}: {message}")]
    Recording { recording: String, message: String },

    /// A JSON document that is not a valid plan or model.
    #[error("{context}: {}", short_numbers(.message))]
    Json { context: String, message: String },

    /// A joint `<limit>` that no joint can have: lower above upper, a speed, effort or
    /// acceleration limit that is zero or negative.
    #[error("{location}: joint '{joint}' <limit>: {message}")]
    InvalidLimit {
        location: Box<Location>,
        joint: String,
        message: String,
    },

    /// A joint's armature (reflected rotor inertia) that cannot be used: not a number, negative,
    /// given twice, or on a joint that does not drive its own degree of freedom.
    #[error("{location}: joint '{joint}' armature: {message}")]
    InvalidArmature {
        location: Box<Location>,
        joint: String,
        message: String,
    },

    /// A joint's `<dynamics>` that no passive joint has: a negative damping or friction (it
    /// would push the joint instead of resisting its motion).
    #[error("{location}: joint '{joint}' <dynamics>: {message}")]
    InvalidDynamics {
        location: Box<Location>,
        joint: String,
        message: String,
    },

    /// A model with no degree of freedom: every joint is fixed or locked.
    #[error("{source_name}: robot '{robot}' has no moving joint (every joint is fixed or locked); nothing can be identified")]
    NoDegreeOfFreedom { source_name: String, robot: String },

    /// A model with more moving bodies than [`crate::limits::MAX_BODIES`]: its buffers alone
    /// (10 n^2 values a regressor, eight times over for the SIMD lanes) would not fit in memory.
    #[error("{source_name}: robot '{robot}' has {bodies} moving bodies; at most {limit} are supported (each sample's regressor has 10 n^2 values; docs/limits.md)")]
    TooManyBodies {
        source_name: String,
        robot: String,
        bodies: usize,
        limit: usize,
    },

    /// Long work stopped by the user (Ctrl-C); nothing was written.
    #[error("{context}: interrupted")]
    Interrupted { context: String },

    /// A model that cannot be written as URDF (see `crate::urdf::write_urdf`).
    #[error("cannot write a URDF of '{robot}': {element}: {message}")]
    UrdfExport {
        robot: String,
        element: String,
        message: String,
    },

    /// A bug of this library (a panic), caught at its boundary.
    #[error("internal error in {context}: {message} (a bug in perturbid_rs: please report it)")]
    Internal { context: String, message: String },

    /// A file of an output set whose writing was interrupted (its manifest is still in state
    /// `"writing"`): the set may mix old and new files.
    #[error("{path} belongs to an output set whose writing was interrupted (see {manifest}): it may mix old and new files; run the command that wrote it again")]
    PartialOutput { path: String, manifest: String },

    /// A configuration file (TOML: a pipeline, a study) that does not say what is expected;
    /// `location` is `file:line:column` or `file, step K`.
    #[error("{location}: {}", short_numbers(.message))]
    Config { location: String, message: String },

    /// A built-in robot or variant name that does not exist.
    #[error("unknown robot '{name}'; built-in robots: {}", available.join(", "))]
    UnknownRobot {
        name: String,
        available: Vec<String>,
    },
}

impl Error {
    /// An argument outside its admissible range: [`Error::InvalidArgument`].
    pub fn invalid(argument: impl Into<String>, message: impl Into<String>) -> Error {
        Error::InvalidArgument {
            argument: argument.into(),
            message: message.into(),
        }
    }

    /// An argument of the wrong length or shape: [`Error::Shape`].
    pub fn shape(
        argument: impl Into<String>,
        expected: impl Into<String>,
        got: impl Into<String>,
    ) -> Error {
        Error::Shape {
            argument: argument.into(),
            expected: expected.into(),
            got: got.into(),
        }
    }

    /// A numerical failure in `operation`: [`Error::Numerical`].
    pub fn numerical(operation: impl Into<String>, message: impl Into<String>) -> Error {
        Error::Numerical {
            operation: operation.into(),
            message: message.into(),
        }
    }

    /// A recording that cannot be used: [`Error::Recording`].
    pub fn recording(recording: impl Into<String>, message: impl Into<String>) -> Error {
        Error::Recording {
            recording: recording.into(),
            message: message.into(),
        }
    }

    /// The kind of problem.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Error::Io { .. } | Error::PartialOutput { .. } => ErrorKind::File,
            Error::Shape { .. }
            | Error::NonFiniteInput { .. }
            | Error::InvalidArgument { .. }
            | Error::LimitViolation(_)
            | Error::Recording { .. }
            | Error::Json { .. }
            | Error::Config { .. } => ErrorKind::Input,
            Error::Numerical { .. } | Error::RankDeficient { .. } => ErrorKind::Numerical,
            Error::UrdfSyntax { .. }
            | Error::UnsupportedJoint { .. }
            | Error::RootCount { .. }
            | Error::Cycle { .. }
            | Error::DuplicateChild { .. }
            | Error::DuplicateName { .. }
            | Error::UnknownLink { .. }
            | Error::JointReference { .. }
            | Error::InvalidInertia { .. }
            | Error::MasslessSubtree { .. }
            | Error::InvalidAxis { .. }
            | Error::MissingLimit { .. }
            | Error::NonFiniteUrdf { .. }
            | Error::InvalidLimit { .. }
            | Error::InvalidArmature { .. }
            | Error::InvalidDynamics { .. }
            | Error::NoDegreeOfFreedom { .. }
            | Error::TooManyBodies { .. }
            | Error::UrdfExport { .. }
            | Error::UnknownRobot { .. } => ErrorKind::Model,
            Error::Interrupted { .. } => ErrorKind::Interrupted,
            Error::Internal { .. } => ErrorKind::Internal,
        }
    }

    /// The error for a panic caught in `context` (a function name), with the panic's message.
    pub fn from_panic(context: &str, payload: &(dyn std::any::Any + Send)) -> Error {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".into());
        Error::Internal {
            context: context.into(),
            message,
        }
    }

    /// The error as raised at sample `s` of a batch: a non-finite entry's argument becomes
    /// `name[s]`, a numerical failure says `(sample s)`.
    pub fn in_sample(self, s: usize) -> Error {
        match self {
            Error::NonFiniteInput {
                argument,
                index,
                value,
            } => Error::NonFiniteInput {
                argument: format!("{argument}[{s}]"),
                index,
                value,
            },
            Error::Numerical { operation, message } => Error::Numerical {
                operation: format!("{operation} (sample {s})"),
                message,
            },
            other => other,
        }
    }
}

/// A number from input as an error message shows it: as Rust prints it where that is short
/// (0, and magnitudes from 1e-4 to below 1e9), in exponent form otherwise (`1e300`, not 301
/// digits), `NaN` and `inf` as such.
pub(crate) fn shown(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() || a == 0.0 || (1e-4..1e9).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `v` rounded to 5 significant digits, written as [`shown`] writes it: a measured interval or
/// rate in a message (0.009 s, not 0.009000000000000001 s).
pub(crate) fn shown5(v: f64) -> String {
    shown(format!("{v:.4e}").parse().unwrap_or(v))
}

/// `text` with every number of more than [`LONG_NUMBER`] characters written as [`shown`]
/// writes it: the JSON and TOML readers' own messages print a float of 1e300 in 301 digits.
pub(crate) fn short_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len().min(4096));
    let mut rest = text;
    while let Some(start) = rest.find(|c: char| c.is_ascii_digit()) {
        let end = rest[start..]
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .map_or(rest.len(), |e| start + e);
        // a full stop after a number ends the sentence, not the number
        let end = if rest[start..end].ends_with('.') {
            end - 1
        } else {
            end
        };
        let number = &rest[start..end];
        let value = number.parse::<f64>().ok().filter(|v| v.is_finite());
        out.push_str(&rest[..start]);
        match value {
            Some(v) if number.len() > LONG_NUMBER => out.push_str(&shown(v)),
            _ => out.push_str(number),
        }
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

/// The longest number [`short_numbers`] leaves as it is (`u64::MAX` has 20 digits).
const LONG_NUMBER: usize = 24;

/// Runs `f`, turning a panic into [`Error::Internal`] naming `context`: the last line of
/// defence at the library's boundaries (Python, the command line), so that a bug reaches the
/// user as an error, not as an abort.
pub fn catch_panics<T>(context: &str, f: impl FnOnce() -> Result<T>) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f))
        .unwrap_or_else(|payload| Err(Error::from_panic(context, &*payload)))
}

/// `Result` with the library's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {

    #[test]
    fn numbers_in_messages_stay_short() {
        use super::shown;
        assert_eq!(shown(1.839), "1.839");
        assert_eq!(shown(-0.072), "-0.072");
        assert_eq!(shown(0.0), "0");
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(-2.5e-320), "-2.5e-320");
        assert_eq!(shown(123456789.0), "123456789");
        assert_eq!(shown(f64::NAN), "NaN");
        assert_eq!(shown(f64::NEG_INFINITY), "-inf");
    }

    #[test]
    fn long_numbers_in_readers_messages_are_shortened() {
        use super::short_numbers;
        let huge = format!("{}", 1e300);
        assert_eq!(huge.len(), 301);
        let e = super::Error::Json {
            context: "plan.json".into(),
            message: format!(
                "invalid type: floating point `{huge}`, expected a string at line 3 column 12"
            ),
        };
        assert_eq!(
            e.to_string(),
            "plan.json: invalid type: floating point `1e300`, expected a string at line 3 column 12"
        );
        let tiny = format!("{}", -2.5e-300);
        assert_eq!(short_numbers(&format!("value {tiny}.")), "value -2.5e-300.");
        // line numbers, u64s and ordinary decimals stay as they are
        for kept in [
            "line 18446744073709551615 column 7",
            "0.1 and 12.5",
            "1.2.3.4",
            "",
        ] {
            assert_eq!(short_numbers(kept), kept);
        }
        let config = super::Error::Config {
            location: "study.toml:4:9".into(),
            message: format!("invalid value {}", 1e40),
        };
        assert_eq!(config.to_string(), "study.toml:4:9: invalid value 1e40");
    }

    use super::*;

    #[test]
    fn the_error_stays_small() {
        // large context is boxed (locations, limit violations): a `Result<T>` costs little more
        // than its `T` on the happy path
        let size = std::mem::size_of::<Error>();
        assert!(size <= 80, "Error is {size} bytes (128 before the boxing)");
    }
}
