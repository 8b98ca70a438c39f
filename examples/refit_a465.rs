//! Refits the paper's A465 (`a465:kinsheel2010_lumped`, whose links carry the motors' rotor
//! inertia and are not physically consistent) as a consistent robot with an armature per joint,
//! from its own torques, and writes the URDF that ships as `a465:kinsheel2010`.
//!
//! `cargo run --release --example refit_a465 -- OUT.urdf`
//!
//! The torques of the lumped model at 2000 random states within the limits are fitted by
//! consistent least squares (docs/parameters.md) with the armature as a parameter; the prior,
//! which decides what the torques do not, is the CAD set (`a465:physical`) with each joint's
//! lumped rotor inertia J_k as its armature.

use perturbid_rs::direct::{
    identify_consistent_parameters, BaseOptions, ConsistentOptions, FrictionTerms, Weighting,
};
use perturbid_rs::{parallel, robots, Gravity, Model, States};

const J: [f64; 6] = [8.3439, 2.9223, 2.4280, 1.2404, 0.9401, 0.4455];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .ok_or("usage: refit_a465 OUT.urdf")?;
    let lumped = robots::a465::model("kinsheel2010_lumped")?;
    // the prior: CAD links, J_k as armature
    let mut prior: Model = robots::a465::model("physical")?;
    prior.armature = J.to_vec();
    let n = lumped.nv;
    let k = 2000;
    let mut seed = 0x2010u64;
    let mut uniform = |lo: f64, hi: f64| {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
    };
    let mut q = vec![0.0; k * n];
    let mut qd = vec![0.0; k * n];
    let mut qdd = vec![0.0; k * n];
    for s in 0..k {
        for j in 0..n {
            let l = &lumped.limits[j];
            q[s * n + j] = uniform(l.lower, l.upper);
            qd[s * n + j] = uniform(-1.0, 1.0) * l.velocity.min(3.0);
            qdd[s * n + j] = uniform(-1.0, 1.0) * l.acceleration.min(10.0);
        }
    }
    let states = States::new(n, &q, Some(&qd), Some(&qdd))?;
    let mut tau = vec![0.0; k * n];
    parallel::rnea(
        &lumped,
        &mut parallel::Workspace::new(&lumped),
        &states,
        Gravity::Included,
        &mut tau,
    )?;
    let options = BaseOptions {
        friction: FrictionTerms {
            armature: true,
            ..FrictionTerms::NONE
        },
        weighting: Weighting::Ols,
        ..BaseOptions::default()
    };
    let fit = identify_consistent_parameters(
        &prior,
        &states,
        &tau,
        &options,
        &ConsistentOptions::default(),
    )?;
    let s = &fit.solution;
    let robot = fit.robot(&prior)?;
    eprintln!(
        "interior point: {} Newton steps, converged {}; torque RMS against the lumped model {:.3e} N m; consistent {}",
        s.iterations,
        s.converged,
        (s.cost / tau.len() as f64).sqrt(),
        s.report.is_consistent()
    );
    for a in &s.active {
        eprintln!("  at the boundary: {a}");
    }
    eprintln!("armature {:?}", robot.armature);
    let mut text = String::from(
        "<?xml version=\"1.0\"?>\n<!-- CRS A465, variant \"kinsheel2010\": fitted to reproduce Tables 2 and 3 of Kinsheel & Taha\n     (ICARCV 2010), physically consistent, with the motors' reflected rotor inertia as each\n     joint's armature. Written by examples/refit_a465.rs from the lumped fit\n     (`a465:kinsheel2010_lumped`), whose torques it reproduces; see\n     docs/parameters.md. -->\n<robot name=\"a465_kinsheel2010\" version=\"1.2\">\n  <link name=\"base_link\"/>\n",
    );
    for b in &robot.bodies {
        let i = &b.inertia;
        let c = i.com;
        let m = i.inertia_com;
        text.push_str(&format!(
            "  <link name=\"{}\">\n    <inertial>\n      <origin xyz=\"{:.9} {:.9} {:.9}\" rpy=\"0 0 0\"/>\n      <mass value=\"{:.9}\"/>\n      <inertia ixx=\"{:.9e}\" ixy=\"{:.9e}\" ixz=\"{:.9e}\" iyy=\"{:.9e}\" iyz=\"{:.9e}\" izz=\"{:.9e}\"/>\n    </inertial>\n  </link>\n",
            b.link, c.x, c.y, c.z, i.mass, m[(0, 0)], m[(0, 1)], m[(0, 2)], m[(1, 1)], m[(1, 2)], m[(2, 2)]
        ));
    }
    // the joints as the lumped file has them, with the armature added
    let source = robots::a465::urdf("kinsheel2010_lumped")?;
    for (j, name) in robot.joint_names.iter().enumerate() {
        let start = source
            .find(&format!("<joint name=\"{name}\""))
            .ok_or("joint")?;
        let end = start + source[start..].find("</joint>").ok_or("joint end")?;
        text.push_str("  ");
        text.push_str(&source[start..end]);
        text.push_str(&format!(
            "  <dynamics damping=\"0\" armature=\"{:.9}\"/>\n  </joint>\n",
            robot.armature[j]
        ));
    }
    text.push_str("</robot>\n");
    perturbid_rs::io::write_atomic(&out, text.as_bytes())?;
    eprintln!("wrote {out}");
    Ok(())
}
