//! numpy in and out: one sample as shape `(n,)` or a batch as `(k, n)`; results shaped to match.

use nalgebra::DMatrix;
use numpy::{
    AllowTypeChange, PyArray1, PyArrayDescrMethods, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use std::borrow::Cow;

/// An array argument of real numbers: a numpy array or anything `numpy.asarray` takes, as
/// float64 (a copy when of another real dtype). Complex, boolean, string, object and time
/// dtypes are refused with a `TypeError` (which Python names the argument in) instead of
/// numpy's conversion, which drops an imaginary part with only a warning, and reads `True` as 1.
pub(crate) struct ArrayLike<'py>(PyArrayLikeDyn<'py, f64, AllowTypeChange>);

impl<'py> std::ops::Deref for ArrayLike<'py> {
    type Target = PyArrayLikeDyn<'py, f64, AllowTypeChange>;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl<'a, 'py> FromPyObject<'a, 'py> for ArrayLike<'py> {
    type Error = PyErr;

    fn extract(ob: pyo3::Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        refuse_masked(&ob)?;
        // the dtype numpy gives it (lists and scalars converted once, here)
        let array = match ob.cast::<PyUntypedArray>() {
            Ok(a) => a.to_owned(),
            Err(_) => {
                let numpy = ob.py().import("numpy")?;
                numpy
                    .call_method1("asarray", (ob,))?
                    .cast_into::<PyUntypedArray>()?
            }
        };
        let dtype = array.dtype();
        if !matches!(dtype.kind(), b'f' | b'i' | b'u') {
            return Err(PyTypeError::new_err(format!(
                "expected real numbers (an array of floats or integers), got dtype {dtype}"
            )));
        }
        Ok(Self(array.as_any().extract()?))
    }
}

/// Refuses a numpy masked array (`numpy.ma`): its masked entries still hold values, which
/// reading its memory would use as data. A plain ndarray is told by its exact type (a pointer
/// comparison); only subclasses pay for the name.
fn refuse_masked(ob: &pyo3::Borrowed<'_, '_, PyAny>) -> PyResult<()> {
    if ob.is_exact_instance_of::<PyUntypedArray>() {
        return Ok(());
    }
    let masked = ob.get_type().mro().iter().any(|t| {
        t.cast::<pyo3::types::PyType>()
            .is_ok_and(|t| t.name().is_ok_and(|n| n == "MaskedArray"))
    });
    if masked {
        return Err(PyTypeError::new_err(
            "expected an array of real numbers, got a masked array: its masked entries would be \
             read as data (fill them, e.g. a.filled(np.nan), or drop those samples)",
        ));
    }
    Ok(())
}

/// Values a [`Samples`] copies instead of borrowing (a few samples of a robot's joints).
const COPY_UP_TO: usize = 64;

/// A states argument of the `Robot` methods: anything [`ArrayLike`] takes. A small
/// C-contiguous float64 array of one or two dimensions (a single sample, a few samples) is
/// copied while the GIL is held, which costs less than numpy's borrow bookkeeping (a third of
/// a one-sample call); anything else is lent as an [`ArrayLike`].
#[allow(clippy::large_enum_variant)] // on the stack for one call: no allocation is the point
pub(crate) enum Samples<'py> {
    Copied {
        shape: [usize; 2],
        ndim: usize,
        len: usize,
        values: [f64; COPY_UP_TO],
        /// The address range the values were copied from (to refuse it as an output).
        memory: std::ops::Range<usize>,
    },
    Lent(ArrayLike<'py>),
}

impl<'a, 'py> FromPyObject<'a, 'py> for Samples<'py> {
    type Error = PyErr;

    fn extract(ob: pyo3::Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        refuse_masked(&ob)?;
        if let Ok(a) = ob.cast::<PyArrayDyn<f64>>() {
            let (shape, len) = (a.shape(), a.len());
            if shape.len() <= 2 && len <= COPY_UP_TO && a.is_c_contiguous() {
                // SAFETY: the GIL is held from here to the copy's end, and no Rust reference
                // to the array's memory is alive (writes into it go through numpy's borrow
                // checks, which this copy does not need)
                if let Ok(from) = unsafe { a.as_slice() } {
                    let mut values = [0.0; COPY_UP_TO];
                    values[..len].copy_from_slice(from);
                    let mut dims = [0; 2];
                    dims[..shape.len()].copy_from_slice(shape);
                    let start = from.as_ptr() as usize;
                    return Ok(Samples::Copied {
                        shape: dims,
                        ndim: shape.len(),
                        len,
                        values,
                        memory: start..start + 8 * len,
                    });
                }
            }
        }
        Ok(Samples::Lent(ob.extract()?))
    }
}

impl Samples<'_> {
    /// Refuses `out` when it shares memory with this argument, as numpy's borrow checks refuse
    /// an output that is also an input (a copied argument is not borrowed, so this checks it).
    pub(crate) fn check_apart_from(&self, out: &Bound<'_, PyArrayDyn<f64>>) -> Result<()> {
        let Samples::Copied { memory, .. } = self else {
            return Ok(());
        };
        let start = out.data() as usize;
        let end = start + 8 * out.len();
        if start < memory.end && memory.start < end {
            return Err(Error::shape(
                "out",
                "writeable arrays that share no memory with the inputs or each other",
                "an array that is also an input",
            ));
        }
        Ok(())
    }
}

/// An array argument read by [`read_batch`]: its shape and its values in C order.
pub(crate) trait ArrayArg {
    fn dims(&self) -> &[usize];
    /// The values in C (row-major) order: the array's own memory when it is C-contiguous,
    /// a copy otherwise (`as_slice` also accepts Fortran order, whose memory order is not
    /// ours).
    fn values(&self) -> Cow<'_, [f64]>;
}

impl ArrayArg for ArrayLike<'_> {
    fn dims(&self) -> &[usize] {
        self.shape()
    }
    fn values(&self) -> Cow<'_, [f64]> {
        match self
            .is_c_contiguous()
            .then(|| self.as_slice().ok())
            .flatten()
        {
            Some(contiguous) => Cow::Borrowed(contiguous),
            None => Cow::Owned(self.as_array().iter().copied().collect()),
        }
    }
}

impl ArrayArg for Samples<'_> {
    fn dims(&self) -> &[usize] {
        match self {
            Samples::Copied { shape, ndim, .. } => &shape[..*ndim],
            Samples::Lent(a) => a.dims(),
        }
    }
    fn values(&self) -> Cow<'_, [f64]> {
        match self {
            Samples::Copied { values, len, .. } => Cow::Borrowed(&values[..*len]),
            Samples::Lent(a) => a.values(),
        }
    }
}

use crate::error::{Error, Result};
use crate::states::States;

/// Arguments of one call as contiguous row-major buffers that the Rust work reads without the
/// GIL: the numpy arrays' own memory when they are C-contiguous float64 (no copy; numpy's
/// own GIL-free loops read their buffers the same way), copies otherwise.
pub(crate) struct Batch<'a> {
    /// Number of samples.
    pub k: usize,
    /// Whether the call was given single samples (shape `(n,)`).
    pub single: bool,
    /// One buffer per argument, `k * n` values each, sample after sample.
    pub columns: Vec<Cow<'a, [f64]>>,
    /// Whether the fourth argument, after q, qd and qdd, is named `coulomb`: the Coulomb
    /// friction term's column ([`Batch::states`]).
    pub coulomb: bool,
}

/// Reads `args` (name, array-like), each of shape `(n,)` or `(k, n)`, all with the same `k`.
pub(crate) fn read_batch<'a, A: ArrayArg>(n: usize, args: &[(&str, &'a A)]) -> Result<Batch<'a>> {
    // (number of samples, whether given as a batch) of the first argument
    let mut first: Option<(usize, bool)> = None;
    let mut columns = Vec::with_capacity(args.len());
    for (name, arr) in args {
        let shape = arr.dims();
        let this = match shape {
            [len] if *len == n => (1, false),
            [rows, len] if *len == n => (*rows, true),
            _ => {
                return Err(Error::shape(
                    name.to_string(),
                    format!("shape ({n},) or (k, {n})"),
                    format!("shape {shape:?}"),
                ))
            }
        };
        match first {
            None => first = Some(this),
            Some(prev) if prev != this => {
                return Err(Error::shape(
                    name.to_string(),
                    if prev.1 {
                        format!("shape ({}, {n}) like the first argument", prev.0)
                    } else {
                        format!("shape ({n},) like the first argument")
                    },
                    format!("shape {shape:?}"),
                ));
            }
            _ => {}
        }
        // Finiteness is checked by the algorithms, sample by sample (see `in_sample`).
        columns.push(arr.values());
    }
    let (k, batched) = first.unwrap_or((0, false));
    Ok(Batch {
        k,
        single: !batched,
        columns,
        coulomb: args.get(3).is_some_and(|(name, _)| *name == "coulomb"),
    })
}

impl Batch<'_> {
    /// The first three arguments as joint states (q, then qd and qdd when given) of `nv` joints,
    /// checked: a single sample stays single (errors name no sample).
    pub fn states(&self, nv: usize) -> Result<States<'_>> {
        let column = |i: usize| self.columns.get(i).map(|c| &c[..]);
        let q = column(0).unwrap_or(&[]);
        let states = if self.single {
            States::single(nv, q, column(1), column(2))
        } else {
            States::new(nv, q, column(1), column(2))
        }?;
        // a fourth array named coulomb, after q, qd and qdd, is the Coulomb term's column
        match column(3) {
            Some(c) if self.coulomb => states.with_coulomb(c),
            _ => Ok(states),
        }
    }

    /// An error raised at sample `s` of this batch, its argument renamed `name[s]` for a batch.
    pub fn in_sample(&self, s: usize, e: Error) -> Error {
        if self.single {
            return e;
        }
        e.in_sample(s)
    }
}

/// Results up to this many values (1 GiB) are allocated directly; larger ones by numpy, which
/// raises `MemoryError` when the memory is not there.
const DIRECT_ALLOCATION: usize = 1 << 27;

/// Where a batched method writes: the caller's `out` array when given (checked: a float64
/// numpy array of exactly the result's shape, C-contiguous, writeable, sharing no memory with
/// the inputs), a new numpy array otherwise. Either way the Rust work writes the array's own
/// memory: nothing is copied afterwards.
pub(crate) fn output_array<'py>(
    py: Python<'py>,
    out: Option<Bound<'py, PyAny>>,
    k: usize,
    single: bool,
    dims: &[usize],
) -> PyResult<Output<'py>> {
    let mut shape: Vec<usize> = if single { Vec::new() } else { vec![k] };
    shape.extend_from_slice(dims);
    let Some(out) = out else {
        let values = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
        let array = match values {
            // SAFETY: every element is written before the array reaches Python (the algorithms
            // write every entry of their output, and on an error the array is dropped)
            Some(v) if v <= DIRECT_ALLOCATION => unsafe {
                PyArrayDyn::<f64>::new(py, shape, false)
            },
            // numpy's own allocation: a MemoryError when the memory is not there (rust-numpy's
            // direct allocation would panic)
            Some(v) if v <= isize::MAX as usize / 8 => {
                let empty = py.import("numpy")?.call_method1("empty", (shape,))?;
                empty.cast_into::<PyArrayDyn<f64>>()?
            }
            _ => {
                return Err(Error::shape(
                    "the result",
                    "an array that fits in memory",
                    format!("shape {shape:?}"),
                )
                .into())
            }
        };
        return Ok(Output { array, fresh: true });
    };
    let wrong = |got: String| Error::Shape {
        argument: "out".into(),
        expected: format!(
            "a C-contiguous, writeable float64 numpy array of shape {shape:?} (the result's)"
        ),
        got,
    };
    let arr = match out.cast::<PyArrayDyn<f64>>() {
        Ok(a) => a.clone(),
        Err(_) => {
            let kind = match out.cast::<numpy::PyUntypedArray>() {
                Ok(a) => format!("a numpy array of dtype {}", a.dtype()),
                Err(_) => format!(
                    "a {}",
                    out.get_type().name().map_or("?".into(), |n| n.to_string())
                ),
            };
            return Err(wrong(kind).into());
        }
    };
    if arr.shape() != shape.as_slice() {
        return Err(wrong(format!("shape {:?}", arr.shape())).into());
    }
    if !arr.is_c_contiguous() {
        return Err(wrong("an array that is not C-contiguous".into()).into());
    }
    Ok(Output {
        array: arr,
        fresh: false,
    })
}

/// A batched method's result array: one made for the call (`fresh`: nothing else refers to it
/// until it is returned, so it is written without numpy's borrow bookkeeping, which costs more
/// than a one-sample call's work) or the caller's `out` (lent through that bookkeeping).
pub(crate) struct Output<'py> {
    array: Bound<'py, PyArrayDyn<f64>>,
    fresh: bool,
}

impl<'py> Output<'py> {
    /// The array, for returning to Python.
    pub(crate) fn into_any(self) -> Bound<'py, PyAny> {
        self.array.into_any()
    }
}

/// Lends the memory of `out` for writing to `f`: a fresh array directly, the caller's through
/// numpy's borrow checks (which refuse an array that is being read, or not writeable); `inputs`
/// are the call's arguments, refused as outputs too when they were copied rather than borrowed.
pub(crate) fn write_into<T>(
    out: &Output<'_>,
    inputs: &[&Samples<'_>],
    f: impl FnOnce(&mut [f64]) -> Result<T>,
) -> Result<T> {
    write_into_all([out], inputs, |[values]| f(values))
}

/// [`write_into`] for several arrays at once (the outputs of one call): each of the caller's
/// must be distinct and share no memory with the inputs.
pub(crate) fn write_into_all<T, const N: usize>(
    outs: [&Output<'_>; N],
    inputs: &[&Samples<'_>],
    f: impl FnOnce([&mut [f64]; N]) -> Result<T>,
) -> Result<T> {
    let lent = || outs.iter().filter(|o| !o.fresh);
    for out in lent() {
        for input in inputs {
            input.check_apart_from(&out.array)?;
        }
    }
    let mut guards = Vec::with_capacity(N);
    for out in lent() {
        guards.push(out.array.try_readwrite().map_err(|e| {
            Error::shape(
                "out",
                "writeable arrays that share no memory with the inputs or each other",
                format!("an array numpy refuses to lend for writing: {e}"),
            )
        })?);
    }
    let not_contiguous =
        |e: numpy::AsSliceError| Error::shape("out", "C-contiguous arrays", e.to_string());
    let mut lent_slices = Vec::with_capacity(N);
    for guard in &mut guards {
        lent_slices.push(guard.as_slice_mut().map_err(not_contiguous)?);
    }
    let mut lent_slices = lent_slices.into_iter();
    let mut slices = Vec::with_capacity(N);
    for out in outs {
        if out.fresh {
            // SAFETY: the array was made for this call and nothing else refers to it until it
            // is returned (no borrow bookkeeping needed, with or without the GIL)
            slices.push(unsafe { out.array.as_slice_mut() }.map_err(not_contiguous)?);
        } else {
            let Some(s) = lent_slices.next() else {
                unreachable!("one guard per lent array")
            };
            slices.push(s);
        }
    }
    let Ok(slices) = <[&mut [f64]; N]>::try_from(slices) else {
        unreachable!("one slice per array")
    };
    f(slices)
}

/// `f` at the states `q`, `qd`, `qdd` ((n,) each or a batch (k, n)), run with the GIL released
/// (`name` names it in a caught panic's report); its row-major result, n values a state, as an
/// array of the states' shape.
pub(crate) fn at_states<'py>(
    py: Python<'py>,
    n: usize,
    [q, qd, qdd]: [&ArrayLike<'py>; 3],
    name: &str,
    f: impl FnOnce(&crate::states::States<'_>) -> Result<Vec<f64>> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    at_states_with(py, n, [q, qd, qdd], None, name, f)
}

/// [`at_states`] with the Coulomb friction term's column (`coulomb`, shaped as `q`; see
/// [`crate::States::with_coulomb`]) where given.
pub(crate) fn at_states_with<'py>(
    py: Python<'py>,
    n: usize,
    [q, qd, qdd]: [&ArrayLike<'py>; 3],
    coulomb: Option<&ArrayLike<'py>>,
    name: &str,
    f: impl FnOnce(&crate::states::States<'_>) -> Result<Vec<f64>> + Send,
) -> PyResult<Bound<'py, PyAny>> {
    let mut args = vec![("q", q), ("qd", qd), ("qdd", qdd)];
    args.extend(coulomb.map(|c| ("coulomb", c)));
    let batch = read_batch(n, &args)?;
    let states = batch.states(n)?;
    let out = super::detached(py, name, || f(&states))?;
    to_numpy(py, out, batch.k, batch.single, &[n])
}

/// A numpy array of `values` with shape `dims` prefixed by `k` unless `single`.
pub(crate) fn to_numpy<'py>(
    py: Python<'py>,
    values: Vec<f64>,
    k: usize,
    single: bool,
    dims: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let mut shape: Vec<usize> = if single { Vec::new() } else { vec![k] };
    shape.extend_from_slice(dims);
    Ok(PyArray1::from_vec(py, values).reshape(shape)?.into_any())
}

/// A numpy array of shape `(rows, cols)` from a matrix (copied out row by row).
pub(crate) fn matrix_to_numpy<'py>(
    py: Python<'py>,
    m: &nalgebra::DMatrix<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let values: Vec<f64> = m.transpose().iter().copied().collect(); // row-major
    to_numpy(py, values, m.nrows(), false, &[m.ncols()])
}

pub(crate) fn vec1<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyAny> {
    PyArray1::from_slice(py, v).into_any()
}

pub(crate) fn rows<'py>(py: Python<'py>, v: &[f64], n: usize) -> PyResult<Bound<'py, PyAny>> {
    to_numpy(py, v.to_vec(), v.len() / n.max(1), false, &[n])
}

/// A 1-D array-like of length `n` (or a scalar broadcast to `n`).
pub(crate) fn per_joint(name: &str, value: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<f64>> {
    let arr: ArrayLike<'_> = value.extract().map_err(|_| {
        Error::invalid(name, "expected a real number or a sequence of real numbers")
    })?;
    if arr.ndim() == 0 {
        return Ok(vec![
            arr.as_array()
                .iter()
                .copied()
                .next()
                .unwrap_or(f64::NAN);
            n
        ]);
    }
    if arr.shape() != [n] {
        return Err(Error::shape(
            name,
            format!("a number or shape ({n},)"),
            format!("shape {:?}", arr.shape()),
        )
        .into());
    }
    Ok(arr.as_array().iter().copied().collect())
}

pub(crate) fn vector(name: &str, a: &ArrayLike<'_>) -> Result<Vec<f64>> {
    if a.ndim() != 1 {
        return Err(Error::shape(
            name,
            "a 1-D array",
            format!("shape {:?}", a.shape()),
        ));
    }
    Ok(a.as_array().iter().copied().collect())
}

/// A 2-D array-like as a matrix (rows x columns).
pub(crate) fn matrix(name: &str, a: &ArrayLike<'_>) -> Result<DMatrix<f64>> {
    match a.shape() {
        [r, c] => Ok(DMatrix::from_row_iterator(
            *r,
            *c,
            a.as_array().iter().copied(),
        )),
        s => Err(Error::shape(
            name,
            "a 2-D array (joints x harmonics)",
            format!("shape {s:?}"),
        )),
    }
}

/// A model's expansion at a point as a dict: `torque` (n,), `D`, `H`, `G` (n, n), `G_static`
/// (n, n) or None.
pub(crate) fn expansion_dict<'py>(
    py: Python<'py>,
    e: &crate::torque_model::Expansion,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let out = pyo3::types::PyDict::new(py);
    out.set_item("torque", vec1(py, e.torque.as_slice()))?;
    out.set_item("D", matrix_to_numpy(py, &e.d)?)?;
    out.set_item("H", matrix_to_numpy(py, &e.h)?)?;
    out.set_item("G", matrix_to_numpy(py, &e.g)?)?;
    match &e.g_static {
        Some(g) => out.set_item("G_static", matrix_to_numpy(py, g)?)?,
        None => out.set_item("G_static", py.None())?,
    }
    Ok(out)
}

/// Friction terms from Python: None (none), a comma-separated string or a list of names from
/// 'viscous', 'coulomb', 'offset' (or 'all', 'none').
pub(crate) fn friction_terms(
    value: Option<&Bound<'_, PyAny>>,
) -> PyResult<crate::direct::FrictionTerms> {
    let Some(value) = value else {
        return Ok(crate::direct::FrictionTerms::NONE);
    };
    Ok(match value.extract::<String>() {
        Ok(text) => text.parse()?,
        Err(_) => crate::direct::FrictionTerms::from_names(&value.extract::<Vec<String>>()?)?,
    })
}

/// The parts of local models to use, from Python's `use` (a subset of 'torque', 'D', 'H',
/// 'G', 'G_static'; None: all), into `options`.
pub(crate) fn local_parts(
    parts: Option<Vec<String>>,
    options: &mut crate::local::FromLocalOptions,
) -> crate::error::Result<()> {
    let Some(parts) = parts else { return Ok(()) };
    const KNOWN: [&str; 5] = ["torque", "D", "H", "G", "G_static"];
    if let Some(bad) = parts.iter().find(|p| !KNOWN.contains(&p.as_str())) {
        return Err(crate::error::Error::invalid(
            "use",
            format!("'{bad}'; expected some of {}", KNOWN.join(", ")),
        ));
    }
    let on = |k: &str| parts.iter().any(|p| p == k);
    options.use_torque = on("torque");
    options.use_d = on("D");
    options.use_h = on("H");
    options.use_g = on("G");
    options.use_g_static = on("G_static");
    Ok(())
}
