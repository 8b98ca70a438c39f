//! Dynamics of many samples at once: the algorithms run on several samples side by side, one
//! sample per SIMD lane (8 with AVX-512, 4 with AVX2 and FMA; see [`Isa`]), chosen at run time
//! by the processor. Every quantity is stored as a structure of arrays (one `[f64; W]` per
//! scalar), so each operation of a recursion acts on one vector register of samples; the
//! model's constants (placements, axes, inertias) are shared by the lanes. Without a vector
//! instruction set the kernels run the one-sample algorithms in a loop.
//!
//! Kernels: [`rnea_batch`] (inverse dynamics), [`mass_matrix_batch`], [`regressor_batch`] and
//! [`regressor_group`] (the joint-torque regressor), [`derivatives_batch`] (the RNEA
//! derivatives) and [`linearize_batch`] (`T*, D*, H*, G*, Gs`). Each takes a [`LaneData`] of
//! buffers made once per model and thread.
//!
//! Inputs are row-major `k x nv` arrays (sample `s`, dof `j` at `s * nv + j`) of finite values:
//! the kernels check shapes, not values (a [`crate::States`] is checked once for all).

mod derivatives;
mod kinematics;
mod mass_matrix;
mod regressor;
mod rnea;

pub use derivatives::{derivatives_batch, linearize_batch, DerivativesOut, LinearizationsOut};
pub use mass_matrix::mass_matrix_batch;
pub use regressor::{regressor_batch, regressor_group};
#[allow(deprecated)]
pub use rnea::{rnea_batch, rnea_lanes};

use crate::algorithms::regressor::PARAMS_PER_BODY;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::{JointKind, Model};
pub use crate::simd::Isa;
use crate::simd::{
    read_rows, serial, sin_cos, Lanes, Rotation3Lanes, SpatialLanes, Stores, Vector3Lanes,
    ZeroPattern,
};

/// The most samples any instruction set processes side by side (AVX-512's 8); a given
/// [`LaneData`] uses [`LaneData::width`] of them.
pub const LANES: usize = 8;

/// Work buffers of the multi-sample kernels for one model, sized for one instruction set
/// (allocate once per model and thread, reuse).
#[derive(Clone, Debug)]
pub struct LaneData {
    isa: Isa,
    nv: usize,
    nbodies: usize,
    /// The parent and the degree of freedom of every body of the model these buffers were
    /// made for: the kernels keep structural facts in them (the entries of the mass matrix and
    /// the regressor that are zero for every sample, left zero since the buffers were made and
    /// written out without being read), so a model of the same sizes but another tree, or
    /// another assignment of bodies to degrees of freedom, is refused.
    bodies: Vec<(Option<usize>, usize)>,
    /// See [`Self::set_job_output`].
    job_output: usize,
    buffers: Buffers,
}

#[derive(Clone, Debug)]
enum Buffers {
    #[cfg(target_arch = "x86_64")]
    W8(Box<LaneBuffers<8>>),
    /// AVX2's 4 lanes, and the 8-lane buffers (pairs of registers) of the kernels that run
    /// faster so ([`LaneKernel::PAIRS_ON_AVX2`]), made on first use.
    #[cfg(target_arch = "x86_64")]
    W4(Box<LaneBuffers<4>>, Option<Box<LaneBuffers<8>>>),
    Scalar(Box<Data>),
}

/// Where the revolute joints' sines and cosines are computed, for the kinematics a kernel runs
/// after [`LaneBuffers::load`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Trig {
    /// By each kinematic step, in place: for [`kinematics::forward`] (measured: with them
    /// loaded, the RNEA and the regressor of the arms 3-7 % slower, the tree's AVX2 RNEA
    /// 2-16 %).
    InPlace,
    /// By [`LaneBuffers::load`], every revolute joint's into [`LaneBuffers::sin_cos`], in a
    /// loop of their own: for [`kinematics::store_pose_in_base`], where the polynomials were
    /// cut by LLVM's vectoriser into pieces of 4, 2 and 1 lanes interleaved with the
    /// rotation's products (the tree's AVX-512 mass matrix 12-15 % faster loaded).
    Loaded,
}

/// The buffers of the kernels on `W` lanes.
#[derive(Clone, Debug)]
pub(crate) struct LaneBuffers<const W: usize> {
    /// Body coordinates of the loaded lanes (joint units, after mimic couplings).
    pub(crate) qb: Vec<Lanes<W>>,
    pub(crate) vb: Vec<Lanes<W>>,
    pub(crate) ab: Vec<Lanes<W>>,
    /// `(sin, cos)` of the revolute joints' body coordinates `qb`, when loaded with
    /// [`Trig::Loaded`] (the other joints' entries are not used).
    pub(crate) sin_cos: Vec<(Lanes<W>, Lanes<W>)>,
    /// Each body's pose in its parent (rotation by rows, translation).
    pub(crate) rot: Vec<Rotation3Lanes<W>>,
    pub(crate) pos: Vec<Vector3Lanes<W>>,
    /// Cosine and sine of each axis-aligned revolute joint's turn, `[cos x, sign sin x]`: the
    /// forward pass keeps these instead of `rot`, `pos` for such joints.
    pub(crate) cos_sin: Vec<[Lanes<W>; 2]>,
    /// Each body's pose in the base frame and its motion subspace there.
    pub(crate) o_rot: Vec<Rotation3Lanes<W>>,
    pub(crate) o_pos: Vec<Vector3Lanes<W>>,
    pub(crate) o_s: Vec<SpatialLanes<W>>,
    /// Twists, accelerations and wrenches in the body frames (inverse dynamics).
    pub(crate) v: Vec<SpatialLanes<W>>,
    pub(crate) a: Vec<SpatialLanes<W>>,
    pub(crate) f: Vec<SpatialLanes<W>>,
    /// Joint torques by body (inverse dynamics).
    pub(crate) tau: Vec<Lanes<W>>,
    /// The regressor of the loaded lanes, row-major `nv x 10 nbodies`.
    pub(crate) regressor: Vec<Lanes<W>>,
    /// The entries of `regressor` the kernel never writes (a degree of freedom that does not
    /// move the body of the column): structural zeros, written out without being read.
    pub(crate) regressor_zeros: ZeroPattern,
    /// The regressor's ancestors' motion subspaces, each body's in its own axes.
    pub(crate) chain: regressor::Chain<W>,
    /// Body-level mass matrix (row-major `nbodies x nbodies`) and composite inertias.
    pub(crate) m: Vec<Lanes<W>>,
    /// The entries of `m` (or of any row-major `nbodies x nbodies` matrix) that pair a body
    /// with one that is neither an ancestor nor a descendant: structural zeros of the mass
    /// matrix and of the torque derivatives, written without being read (a tree's matrices are
    /// mostly such zeros).
    pub(crate) m_zeros: ZeroPattern,
    pub(crate) composite: Vec<mass_matrix::SymmetricComposite<W>>,
    /// The derivatives' buffers, made on first use.
    pub(crate) derivatives: Option<Box<derivatives::Buffers<W>>>,
    /// Whether the last kernel run vouched that every value it wrote is finite (checked in
    /// registers on the way out; see [`LaneData::wrote_finite`]).
    pub(crate) finite: bool,
    /// Whether the kernels on these buffers run on AVX-512 (and may transpose their results
    /// into the output by 512-bit blocks: `write_rows`).
    pub(crate) wide_stores: bool,
    /// The bytes of output of the whole job the next kernel call is part of (see
    /// [`LaneData::set_job_output`]).
    pub(crate) job_output: usize,
    /// Whether the model of the kernel call under way has 16 degrees of freedom or more, each
    /// its own body's ([`rows_are_dofs`]): set once a call (checked once a group of lanes, it
    /// read every body's record, cold in L1 after the group's stores, each time: the tree's
    /// AVX2 mass matrix 2-3 % slower).
    pub(crate) rows_are_dofs: bool,
}

impl<const W: usize> LaneBuffers<W> {
    /// Buffers for every kernel; `wide_stores` when they run on AVX-512.
    fn new(model: &Model, wide_stores: bool) -> Self {
        let cols = PARAMS_PER_BODY * model.nbodies();
        // the entries `regressor_lanes` writes: a body's columns in the rows of the degrees of
        // freedom of the body and its ancestors
        let mut written = vec![false; model.nv * cols];
        for i in 0..model.nbodies() {
            let mut j = Some(i);
            while let Some(k) = j {
                let at = model.bodies[k].dof * cols + PARAMS_PER_BODY * i;
                written[at..at + PARAMS_PER_BODY].fill(true);
                j = model.bodies[k].parent;
            }
        }
        Self {
            regressor: vec![Lanes::default(); written.len()],
            regressor_zeros: ZeroPattern::new(written),
            chain: regressor::Chain::new(model),
            ..Self::without_regressor(model, wide_stores)
        }
    }

    /// Buffers for every kernel but the regressor's, whose buffer (the largest) is left empty.
    fn without_regressor(model: &Model, wide_stores: bool) -> Self {
        let nb = model.nbodies();
        Self {
            qb: vec![Lanes::default(); nb],
            sin_cos: vec![(Lanes::default(), Lanes::default()); nb],
            vb: vec![Lanes::default(); nb],
            ab: vec![Lanes::default(); nb],
            rot: vec![Rotation3Lanes::default(); nb],
            pos: vec![Vector3Lanes::default(); nb],
            cos_sin: vec![[Lanes::default(); 2]; nb],
            o_rot: vec![Rotation3Lanes::default(); nb],
            o_pos: vec![Vector3Lanes::default(); nb],
            o_s: vec![SpatialLanes::default(); nb],
            v: vec![SpatialLanes::default(); nb],
            a: vec![SpatialLanes::default(); nb],
            f: vec![SpatialLanes::default(); nb],
            tau: vec![Lanes::default(); nb],
            regressor: Vec::new(),
            regressor_zeros: ZeroPattern::default(),
            chain: regressor::Chain::default(),
            m: vec![Lanes::default(); nb * nb],
            m_zeros: ZeroPattern::new((0..nb * nb).map(|e| model.related(e / nb, e % nb))),
            composite: vec![mass_matrix::SymmetricComposite::default(); nb],
            derivatives: None,
            finite: false,
            wide_stores,
            job_output: 0,
            rows_are_dofs: false,
        }
    }

    /// How a kernel that writes `values` output values (f64) in all stores its rows (see
    /// [`Stores`]: 8x8 blocks on AVX-512, non-temporal stores for outputs, or jobs, far larger
    /// than the caches).
    #[inline(always)]
    pub(crate) fn stores(&self, values: usize) -> Stores {
        let bytes = values.saturating_mul(8).max(self.job_output);
        Stores::for_output(self.wide_stores, bytes)
    }

    /// [`LaneBuffers::load`] one value at a time, for any model (mimic couplings, bodies in
    /// another order than their degrees of freedom): lane `l` from the rows starting at
    /// `rows[l]`.
    #[inline(always)]
    fn gather(&mut self, model: &Model, x: [&[f64]; 3], rows: &[usize; W]) {
        for (i, b) in model.bodies.iter().enumerate() {
            let mut lanes = [[0.0; W]; 3];
            for (x, out) in x.iter().zip(&mut lanes) {
                if !x.is_empty() {
                    for (o, r) in out.iter_mut().zip(rows) {
                        *o = b.multiplier * x[r + b.dof];
                    }
                }
            }
            for o in &mut lanes[0] {
                *o += b.offset;
            }
            self.qb[i] = Lanes(lanes[0]);
            self.vb[i] = Lanes(lanes[1]);
            self.ab[i] = Lanes(lanes[2]);
        }
    }

    /// Loads the body coordinates of samples `first..first + W` of the row-major `k x nv`
    /// arrays `[q, qd, qdd]` (empty for zeros) into the lanes; past the last sample the lanes
    /// repeat it.
    #[inline(always)]
    pub(crate) fn load(&mut self, model: &Model, x: [&[f64]; 3], first: usize, trig: Trig) {
        let nv = model.nv;
        let k = x[0].len() / nv.max(1);
        // the sample of each lane: past the last sample, the last again
        let mut rows = [0usize; W];
        for (l, r) in rows.iter_mut().enumerate() {
            *r = (first + l).min(k.max(1) - 1) * nv;
        }
        // each body its own degree of freedom, as most models: whole rows read into the lanes
        // by register transposes from 16 dofs on (measured, AVX-512: the 60-dof tree's inverse
        // dynamics 10 % faster, its derivatives 8 %, regressor 5 %; the arms' kernels 3-8 %
        // slower, their few values not worth the transposes' calls; AVX2's 4 lanes, in-process
        // on a Zen 4: the tree's mass matrix and regressor 1-4 % faster, its derivatives and
        // linearisation level)
        let direct = W.is_multiple_of(4) && self.rows_are_dofs;
        if direct {
            for (x, out) in x.iter().zip([&mut self.qb, &mut self.vb, &mut self.ab]) {
                if x.is_empty() {
                    out.fill(Lanes::default());
                } else {
                    read_rows(x, &rows, out, self.wide_stores);
                }
            }
        } else {
            self.gather(model, x, &rows);
        }
        if trig == Trig::Loaded {
            for (i, b) in serial(model.bodies.iter().enumerate()) {
                if b.kind == JointKind::Revolute {
                    self.sin_cos[i] = sin_cos(self.qb[i]);
                }
            }
        }
    }
}

/// A model whose bodies are its degrees of freedom (not coupled): its armature added in the
/// lanes, `armature[i] * qdd[i]` onto the body torques `tau` (`qdd` the loaded accelerations,
/// [`LaneBuffers::ab`]), before the rows are written: added to the output afterwards, it would
/// read back values just stored.
#[inline(always)]
pub(crate) fn armature_torques<const W: usize>(
    model: &Model,
    tau: &mut [Lanes<W>],
    qdd: &[Lanes<W>],
) {
    debug_assert!(!model.coupled);
    for ((t, a), &arm) in tau.iter_mut().zip(qdd).zip(&model.armature) {
        if arm != 0.0 {
            *t = a.mul_add_s(arm, *t);
        }
    }
}

/// As [`armature_torques`], `armature[i]` onto the diagonal of the body-level row-major
/// `nbodies x nbodies` matrix `m` (the mass matrix).
#[inline(always)]
pub(crate) fn armature_inertia<const W: usize>(model: &Model, m: &mut [Lanes<W>]) {
    debug_assert!(!model.coupled);
    let nb = model.nbodies();
    for (i, &arm) in model.armature.iter().enumerate() {
        if arm != 0.0 {
            m[i * nb + i] = m[i * nb + i] + arm;
        }
    }
}

impl LaneData {
    /// Buffers sized for `model`, for the widest instruction set of this processor
    /// ([`Isa::detect`]).
    pub fn new(model: &Model) -> Self {
        Self::for_isa(model, Isa::detect())
    }

    /// Buffers sized for `model` that run the kernels on `isa`; fails if this processor does
    /// not have it (to compare the paths, or to pin one).
    pub fn with_isa(model: &Model, isa: Isa) -> Result<Self> {
        if !isa.is_available() {
            return Err(Error::numerical(
                "LaneData::with_isa",
                format!(
                    "this processor has no {isa} (it has: {})",
                    Isa::available()
                        .iter()
                        .map(|i| i.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        Ok(Self::for_isa(model, isa))
    }

    /// Buffers of 8 lanes run with AVX2 and FMA (two registers per lane vector): the AVX-512
    /// path's 8-lane code on a processor without AVX-512, for tests (tests/simd_paths.rs).
    /// Fails without AVX2 and FMA. [`LaneData::isa`] says `Avx2Fma`, [`LaneData::width`] 8.
    #[doc(hidden)]
    pub fn eight_lanes_on_avx2(model: &Model) -> Result<Self> {
        let mut lanes = Self::with_isa(model, Isa::Avx2Fma)?;
        #[cfg(target_arch = "x86_64")]
        {
            lanes.buffers = Buffers::W8(Box::new(LaneBuffers::new(model, false)));
        }
        Ok(lanes)
    }

    fn for_isa(model: &Model, isa: Isa) -> Self {
        let buffers = match isa {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => Buffers::W8(Box::new(LaneBuffers::new(model, true))),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2Fma => Buffers::W4(Box::new(LaneBuffers::new(model, false)), None),
            _ => Buffers::Scalar(Box::new(Data::new(model))),
        };
        Self {
            isa: if matches!(buffers, Buffers::Scalar(_)) {
                Isa::Scalar
            } else {
                isa
            },
            nv: model.nv,
            nbodies: model.nbodies(),
            bodies: model.bodies.iter().map(|b| (b.parent, b.dof)).collect(),
            job_output: 0,
            buffers,
        }
    }

    /// The instruction set these buffers run the kernels on.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Samples processed side by side (`self.isa().lanes()`) by the regressor and derivative
    /// kernels (the group size of [`regressor_group`]). On AVX2 the inverse dynamics and the
    /// mass matrix take 8 at a time, in pairs of registers: two independent streams of work
    /// hide their recursions' latency.
    pub fn width(&self) -> usize {
        match &self.buffers {
            #[cfg(target_arch = "x86_64")]
            Buffers::W8(_) => 8,
            #[cfg(target_arch = "x86_64")]
            Buffers::W4(..) => 4,
            Buffers::Scalar(_) => 1,
        }
    }

    /// Entry `(joint, parameter)` (N m per parameter unit) of the regressor of sample `sample`
    /// of the group last given to [`regressor_group`]. Panics past the group's samples or the
    /// model's sizes, like slice indexing.
    #[inline]
    pub fn regressor_entry(&self, sample: usize, joint: usize, parameter: usize) -> f64 {
        let p = PARAMS_PER_BODY * self.nbodies;
        assert!(
            joint < self.nv && parameter < p,
            "regressor entry ({joint}, {parameter}) of a {} x {p} regressor",
            self.nv
        );
        match &self.buffers {
            #[cfg(target_arch = "x86_64")]
            Buffers::W8(b) => b.regressor[joint * p + parameter].0[sample],
            #[cfg(target_arch = "x86_64")]
            Buffers::W4(b, _) => b.regressor[joint * p + parameter].0[sample],
            Buffers::Scalar(d) => {
                assert!(sample == 0, "sample {sample} of a one-sample group");
                d.regressor[(joint, parameter)]
            }
        }
    }

    /// Declares that the kernel calls that follow write parts of one job's output of `bytes`
    /// bytes in all (0: each call is a job of its own, the default), as the batch engine does
    /// when it splits a batch over threads or blocks: past 16 MB (on Intel's processors, the
    /// L2 cache's size: `simd::rows::stream_bytes`) the kernels then store whole cache lines
    /// non-temporally, as they would for one call writing it all. Only the speed depends on
    /// it.
    pub fn set_job_output(&mut self, bytes: usize) {
        self.job_output = bytes;
    }

    /// Whether the last kernel run on these buffers checked every value it wrote to be finite
    /// and found them so (the inverse dynamics, mass matrix, regressor, derivative and
    /// linearisation kernels do, on models without couplings; otherwise, and after
    /// [`Self::forget_finite`], false: the caller checks the output itself).
    pub fn wrote_finite(&self) -> bool {
        match &self.buffers {
            #[cfg(target_arch = "x86_64")]
            Buffers::W8(b) => b.finite,
            #[cfg(target_arch = "x86_64")]
            Buffers::W4(b, _) => b.finite,
            Buffers::Scalar(_) => false,
        }
    }

    /// Clears [`Self::wrote_finite`] (before work that may not run a kernel).
    pub fn forget_finite(&mut self) {
        match &mut self.buffers {
            #[cfg(target_arch = "x86_64")]
            Buffers::W8(b) => b.finite = false,
            #[cfg(target_arch = "x86_64")]
            Buffers::W4(b, _) => b.finite = false,
            Buffers::Scalar(_) => {}
        }
    }

    /// Whether these buffers were made for a model of `model`'s sizes and tree (see `check`).
    pub(crate) fn fits(&self, model: &Model) -> bool {
        self.check(model).is_ok()
    }

    /// Fails unless these buffers were made for a model of `model`'s sizes and tree (every
    /// body's parent and degree of freedom).
    fn check(&self, model: &Model) -> Result<()> {
        let sizes = (self.nv, self.nbodies) == (model.nv, model.nbodies());
        if sizes
            && self
                .bodies
                .iter()
                .copied()
                .eq(model.bodies.iter().map(|b| (b.parent, b.dof)))
        {
            return Ok(());
        }
        Err(Error::shape(
            "lane data",
            format!(
                "buffers for this model ({} dofs, {} bodies): LaneData::new(&model)",
                model.nv,
                model.nbodies()
            ),
            if sizes {
                "buffers for a model of these sizes whose bodies have other parents or degrees \
                 of freedom"
                    .into()
            } else {
                format!("buffers for {} dofs and {} bodies", self.nv, self.nbodies)
            },
        ))
    }
}

/// A kernel over a batch, written once for any lane width `W` and once for the one-sample
/// algorithms; [`dispatch`] runs the version for the buffers' instruction set.
pub(crate) trait LaneKernel {
    type Output;
    /// Whether the kernel runs on 8 lanes in pairs of AVX2 registers where the buffers are
    /// AVX2's 4: for a kernel bound by the latency of its recursions, which two independent
    /// register streams hide (measured: the inverse dynamics 25-35 % faster so, the mass
    /// matrix 5-8 %), not for one that runs out of registers (the derivatives, 10-15 %
    /// slower) or gains nothing (the regressor, level). Such a kernel must not use the
    /// regressor's buffer, which the paired buffers leave empty.
    const PAIRS_ON_AVX2: bool = false;
    /// The kernel on `W` lanes. Implementations are `#[inline(always)]`, so that they are
    /// compiled inside the instruction set's function.
    fn wide<const W: usize>(self, model: &Model, buffers: &mut LaneBuffers<W>) -> Self::Output;
    /// The kernel by the one-sample algorithms.
    fn scalar(self, model: &Model, data: &mut Data) -> Self::Output;
}

/// Runs `kernel` on `lanes` (checked to be `model`'s) compiled for the buffers' instruction
/// set.
pub(crate) fn dispatch<K: LaneKernel<Output = Result<T>>, T>(
    model: &Model,
    lanes: &mut LaneData,
    kernel: K,
) -> Result<T> {
    lanes.check(model)?;
    lanes.forget_finite();
    let (job, direct) = (lanes.job_output, rows_are_dofs(model));
    let out = match &mut lanes.buffers {
        // SAFETY: `W8` and `W4` buffers are made only when the processor has the instruction
        // set (`LaneData::with_isa`, `Isa::detect`).
        #[cfg(target_arch = "x86_64")]
        Buffers::W8(b) if lanes.isa == Isa::Avx512 => {
            (b.job_output, b.rows_are_dofs) = (job, direct);
            unsafe { run_avx512(kernel, model, b) }
        }
        // 8 lanes in pairs of AVX2 registers: the 8-lane code tested where AVX-512 is missing
        // (`LaneData::eight_lanes_on_avx2`)
        #[cfg(target_arch = "x86_64")]
        Buffers::W8(b) => {
            (b.job_output, b.rows_are_dofs) = (job, direct);
            unsafe { run_avx2(kernel, model, b.as_mut()) }
        }
        #[cfg(target_arch = "x86_64")]
        Buffers::W4(b, paired) if K::PAIRS_ON_AVX2 => {
            let p = paired
                .get_or_insert_with(|| Box::new(LaneBuffers::without_regressor(model, false)));
            (p.job_output, p.rows_are_dofs) = (job, direct);
            let out = unsafe { run_avx2(kernel, model, p.as_mut()) };
            // what `LaneData::wrote_finite` reads
            b.finite = p.finite;
            out
        }
        #[cfg(target_arch = "x86_64")]
        Buffers::W4(b, _) => {
            (b.job_output, b.rows_are_dofs) = (job, direct);
            unsafe { run_avx2(kernel, model, b.as_mut()) }
        }
        Buffers::Scalar(d) => kernel.scalar(model, d),
    };
    // the output's non-temporal stores ordered before anything the caller stores next (a
    // thread of the batch engine signalling that its part is done)
    crate::simd::store_fence();
    out
}

/// Whether `model`'s samples are read into the lanes as whole rows (`LaneBuffers::load`):
/// 16 degrees of freedom or more, each body its own, in order, as most models (below 16 the
/// transposes' calls cost more than they save).
fn rows_are_dofs(model: &Model) -> bool {
    let nv = model.nv;
    nv >= 16
        && model.bodies.len() == nv
        && (model.bodies.iter().enumerate())
            .all(|(i, b)| b.dof == i && b.multiplier == 1.0 && b.offset == 0.0)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
unsafe fn run_avx512<K: LaneKernel>(kernel: K, model: &Model, b: &mut LaneBuffers<8>) -> K::Output {
    kernel.wide::<8>(model, b)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn run_avx2<K: LaneKernel, const W: usize>(
    kernel: K,
    model: &Model,
    b: &mut LaneBuffers<W>,
) -> K::Output {
    kernel.wide::<W>(model, b)
}

/// The number of samples `k` in `q` (`q_len` values, `k x nv`); checks that every other argument
/// `(name, length, values per sample)` holds `k` samples too.
pub(crate) fn samples(nv: usize, q_len: usize, others: &[(&str, usize, usize)]) -> Result<usize> {
    let k = q_len / nv.max(1);
    let shape = |name: &str, len: usize, per: usize| {
        Error::shape(
            name,
            format!("{k} samples x {per} values, like q"),
            format!("{len} values"),
        )
    };
    if k * nv != q_len {
        return Err(shape("q", q_len, nv));
    }
    match others.iter().find(|(_, len, per)| *len != k * per) {
        Some(&(name, len, per)) => Err(shape(name, len, per)),
        None => Ok(k),
    }
}
