//! `perturbid parameters`: the robot's parameters from local models on the command line,
//! unconstrained and physically consistent.

mod cli_support;

use cli_support::{fails, ok, s, tmp, write};
use perturbid_rs::robots::a465;
use perturbid_rs::Document;
use perturbid_rs::{mass_matrix, Data};

/// `perturbid parameters` from local models identified at two operating points.
#[test]
fn parameters_from_local_models() {
    let d = tmp("parameters");
    let mut models = vec![];
    for (k, q1) in ["0.7854", "0.2"].iter().enumerate() {
        let op = d.join(format!("op{k}.json"));
        write(
            &op,
            &format!(
                r#"{{"q": [{q1}, 0.3927, -0.5236, 0.0, 1.0472, 0.0], "qd": [0.089, -0.106, 0.022, 0.056, 0.011, 0.014], "qdd": [-0.155, -0.5, 0.034, -0.291, -0.008, 0.171]}}"#
            ),
        );
        let (plan, rec, model) = (
            d.join(format!("plan{k}")),
            d.join(format!("rec{k}")),
            d.join(format!("m{k}.json")),
        );
        ok(&[
            "plan",
            "a465",
            "--op",
            s(&op),
            "--out",
            s(&plan),
            "--experiments",
            "nominal,H,D",
            "--design",
            "orthogonal",
        ]);
        ok(&[
            "simulate",
            "a465",
            s(&plan.join("plan.json")),
            "--out",
            s(&rec),
            "--no-friction",
        ]);
        ok(&[
            "identify",
            s(&plan.join("plan.json")),
            s(&rec),
            "--out",
            s(&model),
        ]);
        models.push(model);
    }
    let out = ok(&[
        "parameters",
        "a465",
        s(&models[0]),
        s(&models[1]),
        "--out",
        s(&d.join("parameters.json")),
    ]);
    assert!(
        out.contains("of the robot's 40 base parameters identified from 2 operating point(s)"),
        "{out}"
    );
    let fit = perturbid_rs::direct::BaseModel::load(d.join("parameters.json")).unwrap();
    let model = a465::model("kinsheel2010").unwrap();
    let m = fit.mass_matrix(&model, &a465::TABLE2_Q).unwrap();
    let mut data = Data::new(&model);
    mass_matrix(&model, &mut data, &a465::TABLE2_Q).unwrap();
    assert!((&m - &data.m).norm() < 1e-6 * data.m.norm());
    let out = ok(&[
        "parameters",
        "a465",
        s(&models[0]),
        s(&models[1]),
        "--consistent",
        "--out",
        s(&d.join("consistent.json")),
    ]);
    assert!(
        out.contains("physically consistent: the weighted residual grows by a factor"),
        "{out}"
    );
    assert!(perturbid_rs::direct::BaseModel::load(d.join("consistent.json")).is_ok());
    fails(
        &["parameters", "a465", s(&d.join("nope.json"))],
        &["nope.json"],
    );
    // a model given twice (one path twice, or a copy) is refused; a second model at the first
    // point, from other recordings, is counted as such
    let out_path = d.join("twice.json");
    let twice = |a: &std::path::Path, needles: &[&str]| {
        fails(
            &[
                "parameters",
                "a465",
                s(&models[0]),
                s(&models[1]),
                s(a),
                "--out",
                s(&out_path),
            ],
            needles,
        );
        assert!(!out_path.exists());
    };
    twice(
        &models[0],
        &["MODELS: ", "m0.json is given twice: each local model once"],
    );
    let copy = d.join("copy.json");
    std::fs::copy(&models[0], &copy).unwrap();
    twice(
        &copy,
        &[&format!(
            "{}: the same local model as {} (the same estimates at the same operating point)",
            s(&copy),
            s(&models[0])
        )],
    );
    let (rec, again) = (d.join("rec0b"), d.join("m0b.json"));
    let plan = d.join("plan0").join("plan.json");
    ok(&[
        "simulate",
        "a465",
        s(&plan),
        "--out",
        s(&rec),
        "--no-friction",
        "--torque-noise",
        "0.001",
        "--seed",
        "7",
    ]);
    ok(&["identify", s(&plan), s(&rec), "--out", s(&again)]);
    let out = ok(&[
        "parameters",
        "a465",
        s(&models[0]),
        s(&models[1]),
        s(&again),
        "--out",
        s(&out_path),
    ]);
    assert!(
        out.contains("identified from 3 local models at 2 operating point(s)"),
        "{out}"
    );
}
