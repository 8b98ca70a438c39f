//! An offset a run (`BaseOptions::offset_per_run`): the streamed factors with the runs'
//! columns equal one dense least-squares solve whose regressor has those columns appended
//! (each run's offset less the runs' mean), across chunks and runs that end mid-chunk; the
//! problem with the runs' offsets minimised over (`JointFactors::profiled`) equals that
//! minimum computed densely, for any parameters.

mod common;

use common::{torques, Rng};
use nalgebra::DMatrix;
use perturbid_rs::direct::streaming::{JointFactors, CHUNK};
use perturbid_rs::direct::{regressor_matrix, BaseParameters, FrictionTerms, ParameterLayout};
use perturbid_rs::regression::least_squares;
use perturbid_rs::robots::a465;
use perturbid_rs::{Gravity, States};

#[test]
fn the_runs_offsets_stream_as_a_dense_fit_with_their_columns() {
    let model = a465::model("physical").unwrap();
    let n = model.nv;
    let layout = ParameterLayout::new(&model, FrictionTerms::ALL);
    let base = BaseParameters::from_random_states(&model, &layout, Gravity::Included, 200, 1e-8, 0)
        .unwrap();
    let mut rng = Rng(29);
    // three runs, the second ending mid-chunk, the third crossing a chunk's end
    let runs = [CHUNK + 300, 500, CHUNK + 77];
    let k: usize = runs.iter().sum();
    let q = rng.vector(k * n, 1.5);
    let qd = rng.vector(k * n, 1.0);
    let qdd = rng.vector(k * n, 2.0);
    let mut tau = torques(&model, &q, &qd, &qdd, Gravity::Included);
    let offsets = [
        [0.3, -0.2, 0.1, 0.0, 0.05, -0.05],
        [-0.1, 0.0, 0.2, 0.1, 0.0, 0.0],
        [0.0, 0.4, -0.1, 0.0, -0.02, 0.03],
    ];
    let run_of = |s: usize| {
        let mut end = 0;
        (0..runs.len())
            .find(|&r| {
                end += runs[r];
                s < end
            })
            .unwrap()
    };
    for (i, t) in tau.iter_mut().enumerate() {
        *t += offsets[run_of(i / n)][i % n] + rng.uniform(-0.05, 0.05);
    }
    let states = States::new(n, &q, Some(&qd), Some(&qdd)).unwrap();
    let factors =
        JointFactors::with_runs(&model, &base, &states, &tau, &[], &runs, Gravity::Included)
            .unwrap();
    let p = base.len();
    let e = runs.len() - 1;
    assert_eq!(factors.unknowns(), p + n * e);
    let mut names = base.names();
    names.extend((0..n * e).map(|c| format!("run column {c}")));
    let sigma = [1.0, 2.0, 0.5, 1.0, 1.5, 0.7];
    let streamed = factors.solve(&sigma, &names).unwrap();
    // dense: the base regressor with, per joint, a column per run after the first: 1 on that
    // run's rows of the joint, -1 on the first run's
    let phi = base.select(&regressor_matrix(&model, &layout, &states, Gravity::Included).unwrap());
    let mut a = DMatrix::zeros(k * n, p + n * e);
    a.view_mut((0, 0), (k * n, p)).copy_from(&phi);
    for row in 0..k * n {
        let (s, j) = (row / n, row % n);
        let r = run_of(s);
        for c in 0..e {
            a[(row, p + j * e + c)] = match r {
                0 => -1.0,
                r if r == c + 1 => 1.0,
                _ => 0.0,
            };
        }
    }
    let mut y = DMatrix::from_column_slice(k * n, 1, &tau);
    for row in 0..k * n {
        a.row_mut(row).scale_mut(1.0 / sigma[row % n]);
        y[row] /= sigma[row % n];
    }
    let dense = least_squares(&a, &y, "dense", &names).unwrap();
    let scale = dense.coef.amax();
    assert!((&streamed.coef - &dense.coef).amax() < 1e-9 * scale);
    assert!((&streamed.stderr - &dense.stderr).amax() < 1e-8 * dense.stderr.amax());
    // the runs' deviations are the offsets less their mean, to the noise
    for (r, own) in offsets.iter().enumerate().skip(1) {
        for (j, &offset) in own.iter().enumerate() {
            let mean = offsets.iter().map(|o| o[j]).sum::<f64>() / 3.0;
            let d = streamed.coef[p + j * e + r - 1];
            assert!((d - (offset - mean)).abs() < 0.01, "joint {j} run {r}: {d}");
        }
    }

    // profiled: for any parameters, the problem in them alone is the dense minimum over the
    // runs' columns, reached at `others`
    let profiled = factors.profiled(&sigma).unwrap();
    let runs_part = a.columns(p, n * e).into_owned();
    for trial in 0..3 {
        let theta: Vec<f64> = (0..p)
            .map(|i| streamed.coef[i] * (1.0 + 0.1 * trial as f64) + rng.uniform(-0.1, 0.1))
            .collect();
        let theta_v = DMatrix::from_column_slice(p, 1, &theta);
        let rest = &y - a.columns(0, p) * &theta_v;
        let best = least_squares(&runs_part, &rest, "dense runs", &names[p..]).unwrap();
        let d = best.coef.transpose();
        let dense_min = (&rest - &runs_part * &d).norm_squared();
        let own = (&profiled.r * &theta_v - &profiled.z).norm_squared() + profiled.rho.powi(2);
        assert!(
            (own - dense_min).abs() < 1e-9 * dense_min,
            "{own} vs {dense_min}"
        );
        let others = profiled.others(&theta).unwrap();
        let gap = (0..n * e)
            .map(|c| (others[c] - d[c]).abs())
            .fold(0.0, f64::max);
        assert!(gap < 1e-9 * d.amax().max(1.0), "{gap}");
    }
    // refused: one run, runs that are not the samples'
    for bad in [&[k][..], &[k - 1, 2][..], &[k, 0][..]] {
        let e = JointFactors::with_runs(&model, &base, &states, &tau, &[], bad, Gravity::Included)
            .unwrap_err()
            .to_string();
        assert!(e.contains("runs"), "{e}");
    }
}
