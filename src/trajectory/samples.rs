//! A trajectory sampled on a time grid.

/// Samples of a joint trajectory, row-major: sample `i` of joint `j` is `q[i * n + j]`.
///
/// `t` in s; `q` in rad (or m), `qd` in rad/s, `qdd` in rad/s^2.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Samples {
    /// Number of joints.
    pub n: usize,
    pub t: Vec<f64>,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
}

impl Samples {
    /// Empty samples of `n` joints with room for `capacity` samples.
    pub fn with_capacity(n: usize, capacity: usize) -> Self {
        Self {
            n,
            t: Vec::with_capacity(capacity),
            q: Vec::with_capacity(capacity * n),
            qd: Vec::with_capacity(capacity * n),
            qdd: Vec::with_capacity(capacity * n),
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Positions of sample `i` (length `n`).
    pub fn q_at(&self, i: usize) -> &[f64] {
        &self.q[i * self.n..(i + 1) * self.n]
    }

    /// Velocities of sample `i` (length `n`).
    pub fn qd_at(&self, i: usize) -> &[f64] {
        &self.qd[i * self.n..(i + 1) * self.n]
    }

    /// Accelerations of sample `i` (length `n`).
    pub fn qdd_at(&self, i: usize) -> &[f64] {
        &self.qdd[i * self.n..(i + 1) * self.n]
    }
}
