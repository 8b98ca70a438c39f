"""perturbid_rs side by side with Pinocchio on the A465, the Panda and a 60-dof tree.

    python benches/compare_pinocchio.py [--rounds 5] [--samples 2048] [--no-write]

Needs `pip install pin` (and example-robot-data for the Panda). Pinocchio runs in C++ one call
per sample (benches/pinocchio_peer.cpp, built here with g++ against the `pin` wheel's headers
and libraries and Debian's Eigen, `-O3 -march=native`, see `peer_flags`); without a compiler or
Eigen it runs from Python one call at a time (its figures then include Python's call overhead,
and the table says so). perturbid_rs runs its batched kernels through the Python API on the same
samples, writing into preallocated arrays (`out=`).

For each robot and kernel: `rounds` rounds, each `passes` passes of Pinocchio and of
perturbid_rs over the same samples in alternation (Pinocchio's, ours, Pinocchio's, ...; the C++
peer stays running between its passes), so that a slow spell of the shared machine, which can
last a fraction of a second, falls on both sides. Either side's pass is one untimed call over
the samples (the caches and the clock are cold after the other side's), then calls for at least
20 ms, timed together; a round takes each side's median pass. Each round starts with both sides'
memory allocated anew (our Robot with its buffers, the samples, the outputs; the peer's samples,
Data and outputs), because where it lands in physical memory decides 10-20 % of a kernel's time
on a virtual machine, now and then far more, and would otherwise hold for the whole run: the
rounds sample it. Figures are medians over the rounds, the noise the spread of the per-round
ratios (machine and placement together). One core: batches below the library's parallel
threshold run on the calling thread, and one Pinocchio process. The peer is built
`-march=native`, without AVX-512 when our side's path is capped below it
(`PERTURBID_SIMD=avx2+fma`, standing in for a processor without it: see `peer_flags`). All
cores: a batch large enough for the parallel engine against one Pinocchio process per core.
Results are checked to agree (torques and matrices to 1e-10 relative, the parameters identified
from either library's regressor to 1e-8 relative) before any time is reported. The Markdown
table goes to stdout and to benches/README.md (between the `speed-table` markers).
"""

from __future__ import annotations

import argparse
import ctypes
import functools
import hashlib
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# numpy's BLAS threads would spin beside our one-core runs (nothing here calls BLAS)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

import perturbid_rs as pr  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
PEER = ROOT / "benches" / "pinocchio_peer.cpp"
OUTPUT_CAP = 128 << 20  # bytes of output per timed batch (a 60-dof regressor is 288 kB a sample)
ROBOT_NAMES = ["a465", "panda", "tree60"]
KERNELS = ["rnea", "mass_matrix", "regressor", "rnea_derivatives", "linearize", "forward_dynamics"]
# each side's pass: one untimed call, then calls for at least this long (ms)
WARM_MS = 20
FLAGS = ["-O3", "-march=native", "-DNDEBUG", "-std=c++17", "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
         "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30", "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
         "-DBOOST_FUSION_INVOKE_MAX_ARITY=12"]


# The goals, one core, against Pinocchio's one-call throughput: the kernels of the
# lanes 10x with AVX-512 and 8x with AVX2 and FMA only; the derivatives and the linearisation 5x
# on either; none for forward dynamics (ABA or CRBA, each where faster) or the scalar path; one
# Python call within 1.1x of `pinocchio.rnea`'s time
PYTHON_CALL_TARGET = 1.1


def target(kernel: str, isa: str) -> float | None:
    """The speed-up goal for `kernel` on the `isa` path, or None where it sets none."""
    if isa not in ("avx512", "avx2+fma"):
        return None
    if kernel in ("rnea", "mass_matrix", "regressor"):
        return 10.0 if isa == "avx512" else 8.0
    if kernel in ("rnea_derivatives", "linearize"):
        return 5.0
    return None


def verdict(rows, isa: str, call_ratio: float) -> str:
    """One sentence on the goals from the table's `rows` (robot, kernel, median ratio,
    lowest round's ratio) and one Python call's time ratio: which are met by the median, and
    which of those also in every round."""
    met, short, edge = [], [], []
    for name, kernel, median, lowest in rows:
        goal = target(kernel, isa)
        if goal is None:
            continue
        where = f"{name} {kernel} ({median:.2f}x of {goal:g}x)"
        if median < goal:
            short.append(where)
        elif lowest < goal:
            edge.append(where)
        else:
            met.append(where)
    call = f"one Python call {call_ratio:.2f}x of `pinocchio.rnea`'s time (goal <= {PYTHON_CALL_TARGET}x)"
    (met if call_ratio <= PYTHON_CALL_TARGET else short).append(call)
    if isa not in ("avx512", "avx2+fma"):
        return f"Goals: none for the {isa} path but the Python call: " + call + "."
    out = f"Goals on the {isa} path: {len(met) + len(edge)} of " \
          f"{len(met) + len(edge) + len(short)} met by the median"
    if edge:
        out += "; in the median but not in every round: " + ", ".join(edge)
    out += "; short: " + (", ".join(short) if short else "none") + "."
    return out


def robots():
    """(name, perturbid_rs Robot, Pinocchio model, a function that makes the Robot anew) of the
    A465, the Panda and the tree (with our robots' armature: URDF has no element for it that
    Pinocchio reads)."""
    out = []
    for name, make, model in _robots():
        ours = make()
        out.append((name, ours, with_armature(model, ours), make))
    return out


def with_armature(model, ours):
    perm = [ours.joint_names.index(model.names[j]) for j in range(1, model.njoints)]
    model.armature = np.asarray(ours.armature)[perm]
    return model


def _robots():
    text = pr.robots.a465_urdf("kinsheel2010")
    out = [("a465", lambda: pr.Robot.from_urdf_string(text, check_triangle_inequality=False),
            pin.buildModelFromXML(text))]
    import sysconfig

    path = Path(sysconfig.get_paths()["purelib"]) / \
        "cmeel.prefix/share/example-robot-data/robots/panda_description/urdf/panda.urdf"
    if path.is_file():
        fingers = ["panda_finger_joint1", "panda_finger_joint2"]
        full = pin.buildModelFromUrdf(str(path))
        panda = pin.buildReducedModel(full, [full.getJointId(j) for j in fingers],
                                      pin.neutral(full))
        # ours: the mimic follower goes with the joint it follows
        out.append(("panda", lambda: pr.Robot.from_urdf(str(path), lock={fingers[0]: 0.0}),
                     panda))
    else:
        print(f"skipped the Panda (no {path}): pip install example-robot-data", file=sys.stderr)
    tree = (ROOT / "benches" / "tree60.urdf").read_text()
    out.append(("tree60", lambda: pr.Robot.from_urdf_string(tree), pin.buildModelFromXML(tree)))
    return out


def peer_flags(isa: str) -> list[str]:
    """The peer's compiler flags for our side's `isa` path: `-march=native`, and
    `-mno-avx512f` when our side runs below AVX-512 on a processor that has it (capped by
    `PERTURBID_SIMD`, to stand in for a processor without AVX-512, such as a Zen 3): there
    `-march=native` gives no AVX-512 to Pinocchio's Eigen either. (Measured on the Zen 4:
    the peer without AVX-512 was up to 9 % faster for RNEA, 2-12 % for the regressor, 6-12 %
    slower for the derivatives.)"""
    if isa != "avx512" and "avx512f" in cpu_flags():
        return [*FLAGS, "-mno-avx512f"]
    return list(FLAGS)


def cpu_flags() -> set[str]:
    """The first processor's flags in /proc/cpuinfo (empty where there is none)."""
    return set(cpuinfo("flags").split())


def build_peer(flags: list[str] = FLAGS) -> Path | None:
    """The compiled C++ peer (cached by source, wheel and `flags`), or None when it cannot be."""
    prefix = Path(pin.__file__).resolve()
    while prefix.name != "cmeel.prefix" and prefix != prefix.parent:
        prefix = prefix.parent
    eigen = next((p for p in [Path("/usr/include/eigen3"), prefix / "include/eigen3"]
                  if (p / "Eigen/Core").exists()), None)
    if prefix.name != "cmeel.prefix" or eigen is None or shutil.which("g++") is None:
        print("no C++ peer (needs g++, Eigen and the pin wheel's headers): Pinocchio runs "
              "from Python", file=sys.stderr)
        return None
    key = hashlib.sha256(PEER.read_bytes() + pin.__version__.encode()
                         + " ".join(flags).encode()).hexdigest()[:16]
    exe = Path.home() / ".cache" / "perturbid_rs" / f"pinocchio_peer-{key}"
    if exe.exists():
        return exe
    exe.parent.mkdir(parents=True, exist_ok=True)
    print("building the Pinocchio C++ peer (about 2 minutes, once)...", file=sys.stderr)
    tmp = exe.with_suffix(".tmp")
    cmd = ["g++", *flags, f"-I{prefix / 'include'}", f"-I{eigen}", str(PEER), "-o", str(tmp),
           f"-L{prefix / 'lib'}", f"-Wl,-rpath,{prefix / 'lib'}", "-lpinocchio_default",
           "-lboost_serialization"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        print("the C++ peer did not build; Pinocchio runs from Python:\n"
              + done.stderr[-2000:], file=sys.stderr)
        return None
    tmp.rename(exe)
    return exe


class Side:
    """The samples of one robot and both libraries' runs on them."""

    def __init__(self, name, robot, model, k, workdir, peer, make):
        self.name, self.robot, self.model, self.k, self.peer = name, robot, model, k, peer
        self.make = make  # makes `robot` anew (its buffers elsewhere), for `move`
        self.dir = Path(workdir) / name
        self.dir.mkdir(parents=True, exist_ok=True)
        n = robot.n
        if model.nv != n:
            raise SystemExit(f"{name}: Pinocchio has {model.nv} dofs, perturbid_rs {n}")
        # Pinocchio's joint order (depth first) against ours, by name
        names = [model.names[j] for j in range(1, model.njoints)]
        self.perm = np.array([names.index(j) for j in robot.joint_names])  # ours j -> pin
        rng = np.random.default_rng(0)
        self.x = {"q": rng.uniform(-3, 3, (k, n)), "qd": rng.uniform(-2, 2, (k, n)),
                  "qdd": rng.uniform(-2, 2, (k, n)), "tau": rng.uniform(-2, 2, (k, n))}
        inv = np.argsort(self.perm)
        for key, v in self.x.items():  # pin's column p is our joint inv[p]
            np.ascontiguousarray(v[:, inv]).tofile(self.dir / f"{key}.bin")
        model.saveToBinary(str(self.dir / "model.bin"))
        self.out = self.outputs(k)
        self.server = None  # the C++ peer in its `serve` mode, started by the first pass

    def per_sample(self, kernel):
        """Output values per sample of `kernel`."""
        n, p = self.robot.n, self.robot.parameters.size
        return {"rnea": n, "mass_matrix": n * n, "regressor": n * p,
                "rnea_derivatives": n + 3 * n * n, "linearize": n + 4 * n * n,
                "forward_dynamics": n}[kernel]

    def samples_for(self, kernel):
        """This side's samples, fewer for a kernel whose outputs would pass OUTPUT_CAP."""
        return max(64, min(self.k, OUTPUT_CAP // (8 * self.per_sample(kernel))))

    def outputs(self, k):
        """Output arrays of every kernel for `k` samples (each at most `samples_for` it)."""
        return {kernel: self.output_for(kernel, min(k, self.samples_for(kernel)))
                for kernel in KERNELS}

    def output_for(self, kernel, k):
        """The output array (or tuple of arrays) of `kernel` for `k` samples."""
        n, p = self.robot.n, self.robot.parameters.size

        def e(shape):  # written once here, so that no timed pass pays for first-touch faults
            return np.full(shape, 0.0)

        if kernel == "mass_matrix":
            return e((k, n, n))
        if kernel == "regressor":
            return e((k, n, p))
        if kernel == "rnea_derivatives":
            return (e((k, n)), *(e((k, n, n)) for _ in range(3)))
        if kernel == "linearize":
            return (e((k, n)), *(e((k, n, n)) for _ in range(4)))
        return e((k, n))

    def move(self, kernel):
        """Our side's memory for `kernel` allocated anew: the Robot (its kernels' buffers), the
        samples and the output, each made while the old is held (so that it cannot land in the
        same blocks) and the old then dropped. Each round draws so the memory's placement,
        which held for a whole run when it stayed put. Measured on a Zen 4 guest, one process
        per draw: the Panda's AVX2 regressor 222-253 ns a sample with 16 samples a call (the
        same virtual addresses in each, ASLR off), its mass matrix 85-88 ns in most processes
        and 91-150 ns in about one in six, each steady within its process (benches/README.md).
        The peer does the same (`fresh`)."""
        robot = self.make()
        x = {key: v.copy() for key, v in self.x.items()}
        out = self.output_for(kernel, min(self.k, self.samples_for(kernel)))
        self.robot, self.x = robot, x
        self.out = {**self.out, kernel: out}

    def big(self, k, kernel):
        """`k` samples (this side's, repeated) and an output of `kernel` for them."""
        reps = -(-k // self.k)
        x = {key: np.tile(v, (reps, 1))[:k] for key, v in self.x.items()}
        return x, {kernel: self.output_for(kernel, k)}

    def ours(self, kernel, x=None, out=None):
        """Our batched call of `kernel` on the samples `x` into `out` (default: this side's
        first `samples_for(kernel)` samples and outputs)."""
        if x is None:
            k = self.samples_for(kernel)
            x = {key: v[:k] for key, v in self.x.items()}
            out = self.out
            out = {key: tuple(a[:k] for a in v) if isinstance(v, tuple) else v[:k]
                   for key, v in out.items()}
        r = self.robot
        q, qd, qdd = x["q"], x["qd"], x["qdd"]
        if kernel == "rnea":
            return r.rnea(q, qd, qdd, out=out["rnea"])
        if kernel == "mass_matrix":
            return r.mass_matrix(q, out=out["mass_matrix"])
        if kernel == "regressor":
            return r.regressor(q, qd, qdd, out=out["regressor"])
        if kernel == "rnea_derivatives":
            return r.rnea_derivatives(q, qd, qdd, out=out["rnea_derivatives"])
        if kernel == "linearize":
            return r.linearize(q, qd, qdd, out=out["linearize"])
        return r.forward_dynamics(q, qd, x["tau"], out=out["forward_dynamics"])

    def peer_pass(self, kernel, fresh=False):
        """ns per call of `kernel` by Pinocchio over this side's samples, timed as
        `our_pass` times ours: one untimed pass, then passes for at least 20 ms (the C++
        peer kept running in its `serve` mode, so that its passes and ours alternate closely),
        or one pass from Python without the C++ peer. `fresh`: the C++ peer's memory for it
        allocated anew first (as `move` does ours)."""
        if self.peer is None:
            return self.python_pass(kernel)
        if self.server is None:
            self.server = subprocess.Popen(
                [str(self.peer), str(self.dir / "model.bin"), str(self.dir), str(self.k),
                 "serve"], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.server.stdin.write(f"{kernel} {self.samples_for(kernel)} {WARM_MS}"
                                f"{' fresh' if fresh else ''}\n")
        self.server.stdin.flush()
        reply = json.loads(self.server.stdout.readline() or '{"error": "the peer ended"}')
        if "error" in reply:
            raise SystemExit(f"{self.name}: the C++ peer: {reply['error']}")
        return reply["ns_per_call"]

    def close(self):
        """Ends the C++ peer's process, if one was started."""
        if self.server is not None:
            self.server.stdin.close()
            self.server.wait(timeout=60)
            self.server = None

    def python_pass(self, kernel):
        m, d = self.model, self.model.createData()
        inv = np.argsort(self.perm)
        q, qd, qdd, tau = (self.x[k][:, inv] for k in ("q", "qd", "qdd", "tau"))
        f = {"rnea": lambda i: pin.rnea(m, d, q[i], qd[i], qdd[i]),
             "mass_matrix": lambda i: pin.crba(m, d, q[i]),
             "regressor": lambda i: pin.computeJointTorqueRegressor(m, d, q[i], qd[i], qdd[i]),
             "rnea_derivatives": lambda i: pin.computeRNEADerivatives(m, d, q[i], qd[i], qdd[i]),
             "linearize": lambda i: (pin.computeRNEADerivatives(m, d, q[i], qd[i], qdd[i]),
                                     pin.computeGeneralizedGravityDerivatives(m, d, q[i])),
             "forward_dynamics": lambda i: pin.aba(m, d, q[i], qd[i], tau[i])}[kernel]
        k = self.samples_for(kernel)
        t = time.perf_counter()
        for i in range(k):
            f(i)
        return (time.perf_counter() - t) / k * 1e9

    def our_pass(self, kernel):
        """ns per sample of our batched call of `kernel` on this side's samples."""
        return warm_ns(lambda: self.ours(kernel), self.samples_for(kernel))

    def store_pass(self, kernel):
        """ns per sample of only storing `kernel`'s output: zeros into the same arrays, the
        lesser time of the C library's `memset` and of non-temporal stores of whole lines
        (`benches/store_fill.c`, as our kernels write large outputs), about the least time
        any kernel that writes this output can take. (Not numpy's `fill`, which stores
        element by element: 2-3x slower than `memset` on a large array.)"""
        k = self.samples_for(kernel)
        out = self.out[kernel]
        arrays = [a[:k] for a in (out if isinstance(out, tuple) else (out,))]
        assert all(a.flags.c_contiguous for a in arrays)
        spans = [(a.ctypes.data, a.nbytes) for a in arrays]

        def fill():
            for at, size in spans:
                ctypes.memset(at, 0, size)

        times = [warm_ns(fill, k)]
        fill_nt = store_fill()
        if fill_nt is not None:
            def stream():
                for at, size in spans:
                    fill_nt(at, size // 8)
            times.append(warm_ns(stream, k))
        return min(times)


@functools.cache
def store_fill():
    """`fill_nt(address, count)` of benches/store_fill.c (built once per run into a temporary
    directory), or None where it cannot be built (the ceiling then from `memset` alone)."""
    with tempfile.TemporaryDirectory(prefix="perturbid_store_fill-") as work:
        lib = Path(work) / "store_fill.so"
        if not build_c("store_fill.c", lib, "-shared", "-fPIC"):
            return None
        fn = ctypes.CDLL(str(lib)).fill_nt  # stays mapped once the file is gone
    fn.argtypes, fn.restype = [ctypes.c_void_p, ctypes.c_size_t], None
    return fn


def warm_ns(call, samples, min_seconds=WARM_MS / 1000):
    """ns per sample of `call` (which computes `samples` samples): one call untimed (right after
    the peer's passes the caches and the clock are cold), then calls for `min_seconds`."""
    call()
    calls, t = 0, time.perf_counter()
    while True:
        call()
        calls += 1
        elapsed = time.perf_counter() - t
        if elapsed >= min_seconds:
            return elapsed / (calls * samples) * 1e9


def agree(side: Side) -> list[str]:
    """Checks every kernel's results against Pinocchio's (the C++ peer's files, or pin's Python
    calls), and the parameters identified from either regressor; returns the failures."""
    k, perm = min(side.k, 256), side.perm
    m, d = side.model, side.model.createData()
    inv = np.argsort(perm)
    x = {key: v[:k] for key, v in side.x.items()}
    px = {key: v[:, inv] for key, v in x.items()}
    worst: dict[str, tuple[float, float]] = {}

    def check(what, ours, theirs, tol):
        scale = max(1.0, float(np.max(np.abs(theirs))))
        err = float(np.max(np.abs(np.asarray(ours) - np.asarray(theirs)))) / scale
        if not err <= worst.get(what, (0.0, tol))[0]:
            worst[what] = (err, tol)

    def mat(a):  # pin's joint order -> ours, on both axes
        return np.asarray(a)[np.ix_(perm, perm)]

    tau = side.robot.rnea(x["q"], x["qd"], x["qdd"])
    lin = side.robot.linearize(x["q"], x["qd"], x["qdd"])
    der = side.robot.rnea_derivatives(x["q"], x["qd"], x["qdd"])
    mm = side.robot.mass_matrix(x["q"])
    fd = side.robot.forward_dynamics(x["q"], x["qd"], x["tau"])
    phi = side.robot.regressor(x["q"], x["qd"], x["qdd"])
    cols = np.concatenate([np.arange(10 * p, 10 * p + 10) for p in perm])
    pin_phi = np.empty_like(phi)
    for i in range(k):
        q, qd, qdd, t = px["q"][i], px["qd"][i], px["qdd"][i], px["tau"][i]
        check("rnea", tau[i], pin.rnea(m, d, q, qd, qdd)[perm], 1e-10)
        upper = np.triu(pin.crba(m, d, q, pin.Convention.WORLD))
        check("mass matrix", mm[i], mat(upper + np.triu(upper, 1).T), 1e-10)
        pin.computeRNEADerivatives(m, d, q, qd, qdd)
        check("d tau / d q", der[1][i], mat(d.dtau_dq), 1e-10)
        check("d tau / d qd", der[2][i], mat(d.dtau_dv), 1e-10)
        check("linearize H*", lin.H[i], mat(d.dtau_dv), 1e-10)
        check("linearize G*", lin.G[i], mat(d.dtau_dq), 1e-10)
        gs = pin.computeGeneralizedGravityDerivatives(m, d, q)
        check("linearize Gs", lin.G_static[i], mat(gs), 1e-10)
        check("forward dynamics", fd[i], pin.aba(m, d, q, qd, t)[perm], 1e-8)
        pin_phi[i] = pin.computeJointTorqueRegressor(m, d, q, qd, qdd)[perm][:, cols]
    check("regressor", phi, pin_phi, 1e-10)
    # the same identification (minimum-norm least squares) on either library's regressor
    theta_ours = np.linalg.lstsq(phi.reshape(-1, phi.shape[2]), tau.reshape(-1), rcond=None)[0]
    theta_pin = np.linalg.lstsq(pin_phi.reshape(-1, phi.shape[2]), tau.reshape(-1), rcond=None)[0]
    check("identified parameters", theta_ours, theta_pin, 1e-8)
    return [f"{side.name} {what}: differs by {err:.2e} (relative), tolerance {tol:g}"
            for what, (err, tol) in worst.items() if not err <= tol]


def run_kernel(side: Side, kernel: str, rounds: int, passes: int):
    """Medians (ns per sample) of Pinocchio, of ours and of storing the output alone, and the
    per-round ratios. A round: both sides' memory allocated anew (`Side.move`, the peer's
    `fresh`), then `passes` passes of each side in alternation (Pinocchio's, ours,
    Pinocchio's, ...: a spell of the shared machine, which lasts from a fraction of a second
    to minutes, falls on both), each side's median."""
    t_pin, t_our, t_store, ratios = [], [], [], []
    for _ in range(rounds):
        side.move(kernel)
        pairs = [(side.peer_pass(kernel, fresh=i == 0), side.our_pass(kernel))
                 for i in range(passes)]
        p = statistics.median(x[0] for x in pairs)
        o = statistics.median(x[1] for x in pairs)
        t_store.append(min(side.store_pass(kernel) for _ in range(passes)))
        t_pin.append(p)
        t_our.append(o)
        ratios.append(p / o)
    return statistics.median(t_pin), statistics.median(t_our), statistics.median(t_store), ratios


def all_cores(side: Side, kernel: str, rounds: int):
    """Throughput ratio on every core: our parallel engine on a batch of 8,192 samples against
    one Pinocchio process per core; None when that batch's output would pass 4 OUTPUT_CAP."""
    cores = os.cpu_count() or 1
    big_k = 8192
    if big_k * 8 * side.per_sample(kernel) > 4 * OUTPUT_CAP:
        return None
    big, out = side.big(big_k, kernel)
    k_peer = side.samples_for(kernel)
    ratios = []
    for _ in range(rounds):
        if side.peer is None:
            pin_rate = cores * 1e9 / side.python_pass(kernel)
        else:
            procs = [subprocess.Popen([str(side.peer), str(side.dir / "model.bin"),
                                       str(side.dir), str(k_peer), "3"], stdout=subprocess.PIPE,
                                      text=True, env={**os.environ, "PEER_KERNELS": kernel})
                     for _ in range(cores)]
            pin_rate = 0.0
            for proc in procs:
                # the peer's filter matches substrings ("rnea" in "rnea_derivatives"): by name
                line = next(x for x in map(json.loads, proc.communicate()[0].splitlines())
                            if x["kernel"] == kernel)
                pin_rate += 1e9 / line["ns_per_call"]
        our_rate = 1e9 / warm_ns(lambda: side.ours(kernel, big, out), big_k)
        ratios.append(our_rate / pin_rate)
    return statistics.median(ratios)


def flop_counts() -> dict:
    """Flops per sample of our kernels (examples/flop_count.rs), when cargo can build it."""
    if shutil.which("cargo") is None:
        return {}
    done = subprocess.run(["cargo", "run", "--quiet", "--release", "--features", "count-flops",
                           "--example", "flop_count"], cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        print("no flop counts:\n" + done.stderr[-1000:], file=sys.stderr)
        return {}
    rows = [json.loads(x) for x in done.stdout.splitlines() if x.startswith("{")]
    return {(r["robot"], r["kernel"]): r["flops_per_sample"] for r in rows}


def build_c(source: str, output: Path, *flags: str) -> bool:
    """benches/`source` compiled with gcc (`-O2` and `flags`) into `output`; False, with
    gcc's message on standard error, where it cannot be (no gcc, not x86-64)."""
    if shutil.which("gcc") is None:
        print(f"no gcc: {source} not built", file=sys.stderr)
        return False
    built = subprocess.run(["gcc", "-O2", *flags, str(ROOT / "benches" / source), "-o",
                            str(output)], capture_output=True, text=True)
    if built.returncode != 0:
        print(f"{source} did not build:\n" + built.stderr[-1000:], file=sys.stderr)
    return built.returncode == 0


def measured_peak(isa: str) -> float | None:
    """GFlop/s one core issues with fused multiply-adds at the width of our `isa` path
    (benches/peak_flops.c: 512-bit for avx512, 256-bit for avx2+fma), or None (the scalar
    path, or the probe not built). Measured, since neither the number of FMA pipes (one or
    two 512-bit ones on Intel's Xeons, two 256-bit ones on AMD's Zen 3 and 4) nor the clock
    under load can be read off /proc/cpuinfo."""
    bits = {"avx512": "512", "avx2+fma": "256"}.get(isa)
    if bits is None:
        return None
    with tempfile.TemporaryDirectory(prefix="perturbid_peak_flops-") as work:
        exe = Path(work) / "peak_flops"
        if not build_c("peak_flops.c", exe):
            return None
        done = subprocess.run([str(exe), bits], capture_output=True, text=True, check=True)
        return float(json.loads(done.stdout)["gflops"])


def cpu_model() -> str:
    """The processor's name as /proc/cpuinfo gives it ("" where it does not)."""
    return cpuinfo("model name")


def cpuinfo(field: str) -> str:
    """The first processor's `field` in /proc/cpuinfo ("" where there is none)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith(field):
                return line.split(":", 1)[1].strip()
    except (OSError, IndexError):
        pass
    return ""


class pinned:
    """Within the block the calling thread, and every process it starts, runs on `cpus` only
    (Linux's affinity; nothing elsewhere): both sides of a one-core round on the same core."""

    def __init__(self, cpus):
        self.cpus = set(cpus)

    def __enter__(self):
        self.before = os.sched_getaffinity(0) if hasattr(os, "sched_getaffinity") else None
        if self.before is not None:
            os.sched_setaffinity(0, self.cpus)
        return self

    def __exit__(self, *exc):
        if self.before is not None:
            os.sched_setaffinity(0, self.before)


def python_call(side: Side, calls: int = 20000, rounds: int = 5):
    """Time of one single-sample call from Python, ours against pin's (rnea), in turns."""
    inv = np.argsort(side.perm)
    q, qd, qdd = (side.x[k][0] for k in ("q", "qd", "qdd"))
    pq, pqd, pqdd = q[inv], qd[inv], qdd[inv]
    m, d, r = side.model, side.model.createData(), side.robot
    t_pin, t_our = [], []
    for _ in range(rounds):
        t = time.perf_counter()
        for _ in range(calls):
            pin.rnea(m, d, pq, pqd, pqdd)
        t_pin.append((time.perf_counter() - t) / calls * 1e9)
        t = time.perf_counter()
        for _ in range(calls):
            r.rnea(q, qd, qdd)
        t_our.append((time.perf_counter() - t) / calls * 1e9)
    return statistics.median(t_pin), statistics.median(t_our)


def write_between(path: Path, text: str):
    """Replaces the text between the speed-table markers of `path` (atomically)."""
    body = path.read_text()
    start, end = "<!-- speed-table:start -->", "<!-- speed-table:end -->"
    if start not in body or end not in body:
        print(f"{path} has no speed-table markers: not written", file=sys.stderr)
        return
    new = re.sub(re.escape(start) + ".*?" + re.escape(end), lambda _: f"{start}\n{text}\n{end}",
                 body, flags=re.S)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(new)
    tmp.replace(path)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--passes", type=int, default=5)
    ap.add_argument("--samples", type=int, default=2048, help="per one-core batch (< 4096)")
    ap.add_argument("--no-write", action="store_true", help="print only")
    ap.add_argument("--robots", default=",".join(ROBOT_NAMES))
    ap.add_argument("--cpu", type=int, default=None,
                    help="the core of the one-core rounds (default: the lowest allowed)")
    args = ap.parse_args()
    unknown = sorted(set(args.robots.split(",")) - set(ROBOT_NAMES))
    if unknown:
        raise SystemExit(f"--robots: no robot {', '.join(unknown)} "
                         f"(known: {', '.join(ROBOT_NAMES)})")
    isa = pr.simd_isa()
    flags = peer_flags(isa)
    peer = build_peer(flags)
    flops = flop_counts()
    everywhere = os.sched_getaffinity(0) if hasattr(os, "sched_getaffinity") else set()
    # the one-core rounds: Pinocchio's process and our calls in turns on one core, so that a
    # slow spell of that core (on a shared host, a busy neighbour) falls on both sides
    one = {args.cpu if args.cpu is not None else min(everywhere)} if everywhere else set()
    if one and not one <= everywhere:
        raise SystemExit(f"--cpu {args.cpu}: not one of this process's cores {sorted(everywhere)}")
    with pinned(one):
        peak = measured_peak(isa)
    rows, failures, first = [], [], None
    with tempfile.TemporaryDirectory() as work:
        for name, robot, model, make in robots():
            if name not in args.robots.split(","):
                continue
            side = Side(name, robot, model, args.samples, work, peer, make)
            first = first or side
            failures += agree(side)
            if first is side:
                # the engine's threads started before any pinning (they keep the cores they
                # start with): a batch past the parallel threshold
                side.ours("rnea", *side.big(8192, "rnea"))
            for kernel in KERNELS:
                # (the peer's process, started by the first round, keeps this core)
                with pinned(one):
                    t_pin, t_our, t_store, ratios = run_kernel(side, kernel, args.rounds,
                                                               args.passes)
                many = all_cores(side, kernel, max(2, args.rounds // 2))
                f = flops.get((name, kernel))
                rate = f / t_our if f else None
                rows.append((name, kernel, t_pin, t_our, statistics.median(ratios),
                             min(ratios), max(ratios), many, rate, t_pin / t_store))
                print(f"{name:7s} {kernel:17s} pin {t_pin:9.1f} ns  ours {t_our:9.1f} ns  "
                      f"store {t_store:8.1f} ns  "
                      f"x{statistics.median(ratios):5.2f} [{min(ratios):.2f}-{max(ratios):.2f}]"
                      f"  all cores {'n/a' if many is None else f'x{many:.2f}'}", file=sys.stderr)
            side.close()
        with pinned(one):
            call = python_call(first)
    if failures:
        print("RESULTS DIFFER:\n" + "\n".join(failures), file=sys.stderr)
        return 1
    march = " ".join(x for x in flags if x.startswith("-m"))
    who = f"Pinocchio C++ (one call per sample, built `{march}`)" if peer else \
        "Pinocchio from Python (one call per sample, Python's overhead included)"
    lines = [
        f"Measured on {os.cpu_count()} cores of "
        f"{cpu_model() or 'an unnamed processor'} ({isa} path, {isa_lanes(isa)} lanes; the "
        f"one-core rounds on core {min(one) if one else 'any'}), against {who}, "
        f"`python benches/compare_pinocchio.py` (medians of {args.rounds} rounds taken in turns;"
        " the brackets are the lowest and highest per-round ratio: the machine's noise and,"
        " each round on memory allocated anew, its placement's).",
        "",
        "| robot | kernel | Pinocchio ns/sample | perturbid_rs ns/sample | speed-up, one core "
        "| goal | speed-up, all cores | GFlop/s (% of peak) | store-bound ceiling |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, kernel, t_pin, t_our, r, lo, hi, many, rate, ceiling in rows:
        fl = f"{rate:.1f} ({100 * rate / peak:.0f} %)" if rate and peak else "n/a"
        all_ = "n/a (output > 512 MB)" if many is None else f"{many:.2f}x"
        cap = f"{ceiling:.{0 if ceiling >= 100 else 1}f}x"
        goal = target(kernel, isa)
        goal = "-" if goal is None else f"{goal:g}x {'met' if r >= goal else 'short'}"
        lines.append(f"| {name} | {kernel} | {t_pin:.0f} | {t_our:.0f} | {r:.2f}x "
                     f"[{lo:.2f}-{hi:.2f}] | {goal} | {all_} | {fl} | {cap} |")
    lines += ["", f"One `Robot.rnea` call from Python ({first.name}, one sample): "
              f"{call[1]:.0f} ns against {call[0]:.0f} ns for `pinocchio.rnea` "
              f"({call[1] / call[0]:.2f}x its time).",
              verdict([(x[0], x[1], x[4], x[5]) for x in rows], isa, call[1] / call[0])]
    lines.append("Store-bound ceiling: Pinocchio's time over the time it takes only to fill "
                 "the same output arrays with zeros, per sample, the lesser of the C library's "
                 "`memset` and non-temporal stores of whole lines (`benches/store_fill.c`, as "
                 "our kernels write large outputs): about the most a kernel that writes that "
                 "output can gain. Loose where lines hold data: a line of zeros can be stored "
                 "far faster than one holding data (on the Zen 4 measured, 0.7 ns against "
                 "2-3 ns).")
    if peak:
        lines.append(f"Peak: {peak:.0f} GFlop/s, measured on that core before the rounds "
                     f"(`benches/peak_flops.c`: fused multiply-adds {isa_lanes(isa) * 64} bits "
                     "wide, the width of the path measured, twelve independent ones at a time).")
    table = "\n".join(lines)
    print(table)
    if not args.no_write:
        write_between(ROOT / "benches" / "README.md", table)
    return 0


def isa_lanes(isa: str) -> int:
    return {"avx512": 8, "avx2+fma": 4}.get(isa, 1)


if __name__ == "__main__":
    sys.exit(main())
