//! Whether torques include gravity: a named option instead of a bare `bool` at every call site.

use serde::{Deserialize, Serialize};

/// Standard gravity (m/s^2), along -z of the base frame.
pub const STANDARD_GRAVITY: f64 = 9.81;

/// Whether the torques an algorithm computes (or a log holds) include the gravity torque
/// `g(q)`.
///
/// `Excluded` is what the paper assumes (gravity compensated by the controller). In JSON
/// documents it is stored as the boolean `true` (included) or `false` (excluded), so files
/// written before this type existed still load.
///
/// ```
/// use perturbid_rs::Gravity;
/// assert!(Gravity::Included.is_included());
/// assert_eq!(Gravity::from(false), Gravity::Excluded);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(from = "bool", into = "bool")]
pub enum Gravity {
    /// The torques include `g(q)` (the robot as it is).
    #[default]
    Included,
    /// The torques leave `g(q)` out (as if compensated).
    Excluded,
}

impl Gravity {
    /// `true` for [`Gravity::Included`].
    pub fn is_included(self) -> bool {
        self == Gravity::Included
    }
}

impl From<bool> for Gravity {
    fn from(included: bool) -> Self {
        if included {
            Gravity::Included
        } else {
            Gravity::Excluded
        }
    }
}

impl From<Gravity> for bool {
    fn from(g: Gravity) -> bool {
        g.is_included()
    }
}
