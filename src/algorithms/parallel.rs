//! The batch engine: an algorithm over many samples, split over the cores.
//!
//! Every function takes the samples as a checked [`States`] view, writes its results into the
//! caller's row-major buffers, and runs
//! - on the multi-sample kernels of [`super::batch`] ([`LaneData::width`] samples side by side, SIMD)
//!   where one exists (inverse dynamics, mass matrix, regressor, derivatives, linearisation),
//!   one sample at a time otherwise (forward dynamics);
//! - on the calling thread with the caller's [`Workspace`] below [`PARALLEL_BATCH`] samples,
//!   and in chunks of [`PARALLEL_CHUNK`] samples over rayon's thread pool above it, each thread
//!   with its own buffers, kept in the caller's [`Workspace`] from one call to the next (no
//!   allocation per sample, nor per call once made).
//!
//! Results equal the one-sample algorithms up to rounding. Errors name the sample of the batch.

use rayon::prelude::*;
use std::sync::{Mutex, PoisonError};

use super::batch::{
    derivatives_batch, linearize_batch, mass_matrix_batch, regressor_batch, rnea_batch, LaneData,
};
pub use super::batch::{DerivativesOut, LinearizationsOut};
use super::regressor::PARAMS_PER_BODY;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::gravity::Gravity;
use crate::model::Model;
use crate::states::States;

/// Batches of at least this many samples run in parallel.
pub const PARALLEL_BATCH: usize = 4096;
/// Samples per parallel chunk.
pub const PARALLEL_CHUNK: usize = 1024;

/// The buffers of one thread: a [`Data`] for the one-sample algorithms and a [`LaneData`] for
/// the multi-sample kernels, and those of the engine's threads for batches run in parallel
/// (made on the first such batch, kept for the next). Allocate once per model and reuse.
#[derive(Debug)]
pub struct Workspace {
    pub data: Data,
    pub lanes: LaneData,
    /// One workspace per thread of rayon's pool, by thread index (made anew for each chunk,
    /// the 60-dof tree's buffers and their first touch took 14 % of its parallel inverse
    /// dynamics).
    helpers: Vec<Mutex<Option<Workspace>>>,
}

impl Workspace {
    /// Buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        Self {
            data: Data::new(model),
            lanes: LaneData::new(model),
            helpers: Vec::new(),
        }
    }
}

impl Clone for Workspace {
    /// The buffers of this thread; the engine's threads make theirs again when needed.
    fn clone(&self) -> Self {
        Self {
            data: self.data.clone(),
            lanes: self.lanes.clone(),
            helpers: Vec::new(),
        }
    }
}

/// Output values written per block before they are checked for finite values (while they
/// are still in the core's cache: a second pass over a large batch would read it all back
/// from memory).
const CHECK_BLOCK_VALUES: usize = 1 << 14;

/// Runs `f` over the samples of `states`, whose results fill `outs` (`per_sample[i]` values per
/// sample in `outs[i]`): on `ws` for a small batch, in parallel chunks for a large one. Each
/// thread runs its samples in blocks of a few kilobytes of output and checks each block's
/// results to be finite as soon as it is written.
fn run<F>(
    algorithm: &str,
    model: &Model,
    ws: &mut Workspace,
    states: &States<'_>,
    outs: &mut [(&str, &mut [f64], usize)],
    f: F,
) -> Result<()>
where
    F: Fn(&mut Workspace, &States<'_>, &mut [&mut [f64]]) -> Result<()> + Sync,
{
    if states.nv() != model.nv {
        return Err(Error::shape(
            "q",
            format!("{} joints per sample (the model's)", model.nv),
            format!("{} joints per sample", states.nv()),
        ));
    }
    let k = states.len();
    for (name, out, per) in outs.iter() {
        if out.len() != k * per {
            return Err(Error::shape(
                *name,
                format!("{k} samples x {per} values"),
                format!("{} values", out.len()),
            ));
        }
    }
    let layout: Vec<(&str, usize)> = outs.iter().map(|o| (o.0, o.2)).collect();
    // the kernels store as for the whole output, whatever part each call writes
    let job = outs
        .iter()
        .map(|o| o.1.len())
        .sum::<usize>()
        .saturating_mul(8);
    if k < PARALLEL_BATCH || outs.iter().any(|o| o.2 == 0) {
        let mut whole: Vec<&mut [f64]> = outs.iter_mut().map(|o| &mut *o.1).collect();
        ws.lanes.set_job_output(job);
        let done = in_blocks(algorithm, ws, states, &layout, &mut whole, &f);
        ws.lanes.set_job_output(0);
        return done;
    }
    let chunks = k.div_ceil(PARALLEL_CHUNK);
    let mut per_chunk: Vec<Vec<&mut [f64]>> = (0..chunks).map(|_| Vec::new()).collect();
    for (_, out, per) in outs.iter_mut() {
        for (c, part) in out.chunks_mut(PARALLEL_CHUNK * *per).enumerate() {
            per_chunk[c].push(part);
        }
    }
    let threads = rayon::current_num_threads().max(1);
    if ws.helpers.len() != threads {
        ws.helpers = (0..threads).map(|_| Mutex::new(None)).collect();
    }
    let helpers = &ws.helpers;
    per_chunk
        .into_par_iter()
        .enumerate()
        .try_for_each(|(c, mut parts)| {
            crate::interrupt::check(algorithm)?;
            let first = c * PARALLEL_CHUNK;
            let chunk = states.slice(first..(first + PARALLEL_CHUNK).min(k));
            // this thread's own (uncontended: one thread per index); one made for another
            // model is replaced (a poisoned one is whole: its last user failed between calls)
            let t = rayon::current_thread_index().unwrap_or(0) % threads;
            let mut slot = helpers[t].lock().unwrap_or_else(PoisonError::into_inner);
            let ws = match slot.as_mut() {
                Some(ws) if ws.lanes.fits(model) && ws.data.fits(model) => ws,
                _ => slot.insert(Workspace::new(model)),
            };
            ws.lanes.set_job_output(job);
            in_blocks(algorithm, ws, &chunk, &layout, &mut parts, &f)
        })
}

/// `f` over the samples of `states` on one thread, block by block (a multiple of 8 samples,
/// about [`CHECK_BLOCK_VALUES`] output values), each block's results checked as soon as they
/// are written: the first that is not finite (finite inputs so large that the arithmetic
/// overflows) fails, naming the algorithm and the sample, so no inf or NaN is handed back.
/// A block whose lane kernel checked every value it wrote ([`LaneData::wrote_finite`]) is not
/// read back, and the samples after it go in blocks of at least [`PARALLEL_CHUNK`]; `f` must
/// write a block's outputs through one kernel call or none. Between blocks an interrupt
/// (Ctrl-C, [`crate::interrupt`]) stops the work with [`crate::Error::Interrupted`].
/// `layout`: each output's name and values per sample; `outs`: the outputs of `states`.
fn in_blocks<F>(
    algorithm: &str,
    ws: &mut Workspace,
    states: &States<'_>,
    layout: &[(&str, usize)],
    outs: &mut [&mut [f64]],
    f: &F,
) -> Result<()>
where
    F: Fn(&mut Workspace, &States<'_>, &mut [&mut [f64]]) -> Result<()>,
{
    let per_sample: usize = layout.iter().map(|o| o.1).sum();
    let block = (CHECK_BLOCK_VALUES / per_sample.max(1)) / 8 * 8;
    let mut block = block.max(8);
    let k = states.len();
    let mut first = 0;
    loop {
        let end = (first + block).min(k);
        let samples = states.slice(first..end);
        let mut parts: Vec<&mut [f64]> = outs
            .iter_mut()
            .zip(layout)
            .map(|(o, (_, per))| &mut o[first * per..end * per])
            .collect();
        ws.lanes.forget_finite();
        f(ws, &samples, &mut parts)?;
        // a lane kernel that checked its values in registers as it wrote them vouches for them
        let vouched = ws.lanes.wrote_finite();
        for (out, (name, per)) in parts.iter().zip(layout).filter(|_| !vouched) {
            if let Some(i) = crate::finite::first_non_finite_here(out) {
                let per = (*per).max(1);
                return Err(samples.at(i / per, super::overflow(algorithm, name, out[i], i % per)));
            }
        }
        first = end;
        if first >= k {
            return Ok(());
        }
        if vouched {
            // the kernel checks what it writes: the rest in blocks of at least PARALLEL_CHUNK
            // samples (a kernel call has a fixed cost that small blocks of a large model would
            // pay again and again); should it not vouch there, the rest is read back
            block = block.max(PARALLEL_CHUNK);
        }
        // Ctrl-C between blocks: a batch below PARALLEL_BATCH runs here whole (4,000 of the
        // 60-dof tree's regressors into a fresh array: 1.8-2.8 s of first touches)
        crate::interrupt::check(algorithm)?;
    }
}

/// Inverse dynamics `tau = M(q) qdd + c(q, qd) [+ g(q)]` of every sample (rigid bodies, no
/// friction); missing `qd` or `qdd` are zeros, so `States::new(nv, q, None, None)` gives the
/// gravity torques and `qdd = None` the bias torques.
///
/// `tau`: row-major `k x nv` (N m or N).
///
/// ```
/// use perturbid_rs::{parallel, robots, Gravity, States};
/// let model = robots::builtin("a465").unwrap();
/// let q = vec![0.3; 10 * model.nv];
/// let states = States::new(model.nv, &q, None, None).unwrap();
/// let mut ws = parallel::Workspace::new(&model);
/// let mut tau = vec![0.0; q.len()];
/// parallel::rnea(&model, &mut ws, &states, Gravity::Included, &mut tau).unwrap();
/// ```
pub fn rnea(
    model: &Model,
    ws: &mut Workspace,
    states: &States<'_>,
    gravity: Gravity,
    tau: &mut [f64],
) -> Result<()> {
    let n = model.nv;
    run(
        "rnea",
        model,
        ws,
        states,
        &mut [("tau", tau, n)],
        |w, s, out| {
            let out = &mut *out[0];
            // one sample by the one-sample algorithm (the lanes would compute it in every lane:
            // on a Zen 4, level on the arms, the 60-dof tree's 35 % slower); two or more on the
            // lanes (from two on faster on every robot measured)
            if s.len() >= 2 {
                return rnea_batch(model, &mut w.lanes, s.q(), s.qd(), s.qdd(), gravity, out);
            }
            let zeros = vec![0.0; n];
            for (i, o) in out.chunks_mut(n).enumerate() {
                let x = s.sample(i);
                let (qd, qdd) = (x.qd.unwrap_or(&zeros), x.qdd.unwrap_or(&zeros));
                crate::algorithms::rnea::rnea(model, &mut w.data, x.q, qd, qdd, gravity)
                    .map_err(|e| s.at(i, e))?;
                o.copy_from_slice(w.data.tau.as_slice());
            }
            Ok(())
        },
    )
}

/// Joint-space mass matrices `M(q)` of every sample (velocities and accelerations ignored).
///
/// `out`: row-major `k x nv x nv` (kg m^2, kg m or kg), both triangles.
pub fn mass_matrix(
    model: &Model,
    ws: &mut Workspace,
    states: &States<'_>,
    out: &mut [f64],
) -> Result<()> {
    let n = model.nv;
    run(
        "mass_matrix",
        model,
        ws,
        states,
        &mut [("M", out, n * n)],
        // on the lanes however few the samples: one sample as fast as by the one-sample
        // algorithm or faster (on a Zen 4: the arms level, the 60-dof tree 7 % faster), more
        // far faster
        |w, s, out| mass_matrix_batch(model, &mut w.lanes, s.q(), out[0]),
    )
}

/// The joint-torque regressor `Phi(q, qd, qdd)` of every sample (see
/// [`super::regressor::joint_torque_regressor`]): `Phi theta = rnea(q, qd, qdd)` for the
/// inertial parameters `theta` of every body in Pinocchio's order.
///
/// `out`: row-major `k x nv x 10 nbodies` (N m per parameter unit).
pub fn regressor(
    model: &Model,
    ws: &mut Workspace,
    states: &States<'_>,
    gravity: Gravity,
    out: &mut [f64],
) -> Result<()> {
    let (n, p) = (model.nv, PARAMS_PER_BODY * model.nbodies());
    run(
        "regressor",
        model,
        ws,
        states,
        &mut [("the regressor", out, n * p)],
        // on the lanes however few the samples: one sample 1.5x (the arms) to 3x (the 60-dof
        // tree) faster than by the one-sample algorithm and a copy into rows (on a Zen 4)
        |w, s, out| {
            let (qd, qdd) = (s.qd_or_zeros(), s.qdd_or_zeros());
            regressor_batch(model, &mut w.lanes, s.q(), &qd, &qdd, gravity, out[0])
        },
    )
}

/// Forward dynamics `qdd = M(q)^-1 (tau - c(q, qd) [- g(q)])` of every sample; the
/// accelerations of `states` are ignored.
///
/// `tau`: row-major `k x nv` (N m or N), finite. `qdd`: row-major `k x nv` output.
pub fn forward_dynamics(
    model: &Model,
    ws: &mut Workspace,
    states: &States<'_>,
    tau: &[f64],
    gravity: Gravity,
    qdd: &mut [f64],
) -> Result<()> {
    let n = model.nv;
    states.check_companion("tau", tau, n)?;
    run(
        "forward_dynamics",
        model,
        ws,
        states,
        &mut [("qdd", qdd, n)],
        |w, s, out| {
            let zeros = vec![0.0; n];
            // the chunk's torques: its samples sit at the same offset in `tau` as in the batch
            let offset = s.offset() - states.offset();
            for (i, o) in out[0].chunks_mut(n).enumerate() {
                let x = s.sample(i);
                let t = &tau[(offset + i) * n..(offset + i + 1) * n];
                crate::algorithms::forward_dynamics::forward_dynamics(
                    model,
                    &mut w.data,
                    x.q,
                    x.qd.unwrap_or(&zeros),
                    t,
                    gravity,
                )
                .map_err(|e| s.at(i, e))?;
                o.copy_from_slice(w.data.qdd.as_slice());
            }
            Ok(())
        },
    )
}

/// Inverse dynamics and its analytic partial derivatives (see [`crate::rnea_derivatives`]) at
/// every sample, written into `out` (row-major: `tau` `k x nv`, the matrices `k x nv x nv`).
pub fn rnea_derivatives(
    model: &Model,
    ws: &mut Workspace,
    states: &States<'_>,
    gravity: Gravity,
    out: DerivativesOut<'_>,
) -> Result<()> {
    let (n, nn) = (model.nv, model.nv * model.nv);
    let mut outs = [
        ("tau", out.tau, n),
        ("d tau / d q", out.dtau_dq, nn),
        ("d tau / d qd", out.dtau_dv, nn),
        ("M", out.m, nn),
    ];
    run(
        "rnea_derivatives",
        model,
        ws,
        states,
        &mut outs,
        |w, s, out| {
            let (qd, qdd) = (s.qd_or_zeros(), s.qdd_or_zeros());
            if let [tau, dtau_dq, dtau_dv, m] = out {
                let out = DerivativesOut {
                    tau,
                    dtau_dq,
                    dtau_dv,
                    m,
                };
                return derivatives_batch(model, &mut w.lanes, s.q(), &qd, &qdd, gravity, out);
            }
            unreachable!("four outputs")
        },
    )
}

/// The analytic linearisation (see [`crate::linearize`]) at every sample taken as an operating
/// point, written into `out`.
pub fn linearize(
    model: &Model,
    ws: &mut Workspace,
    states: &States<'_>,
    gravity: Gravity,
    out: LinearizationsOut<'_>,
) -> Result<()> {
    let (n, nn) = (model.nv, model.nv * model.nv);
    let mut outs = [
        ("torque", out.torque, n),
        ("d", out.d, nn),
        ("h", out.h, nn),
        ("g", out.g, nn),
        ("g_static", out.g_static, nn),
    ];
    run("linearize", model, ws, states, &mut outs, |w, s, out| {
        let (qd, qdd) = (s.qd_or_zeros(), s.qdd_or_zeros());
        if let [torque, d, h, g, g_static] = out {
            let out = LinearizationsOut {
                torque,
                d,
                h,
                g,
                g_static,
            };
            return linearize_batch(model, &mut w.lanes, s.q(), &qd, &qdd, gravity, out);
        }
        unreachable!("five outputs")
    })
}
