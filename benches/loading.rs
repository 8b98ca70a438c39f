//! Loading hostile sizes in linear time: `cargo bench --bench loading`. A chain of 20,000 and
//! 100,000 links (the URDF loader was quadratic) and a CSV header of 1,000,000 columns (the
//! duplicate check was quadratic), and a 60 s log at 1 kHz of a 7-joint arm. Each case runs 10 times: the 100,000-link chain takes
//! seconds per run.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use perturbid_rs::io::Table;
use perturbid_rs::{model_from_urdf_str, LoadOptions};

fn chain(n: usize) -> String {
    let mut urdf = String::from(r#"<robot name="chain"><link name="l0"/>"#);
    for i in 1..=n {
        urdf.push_str(&format!(
            "<link name=\"l{i}\"><inertial><mass value=\"1\"/><inertia ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.1\"/></inertial></link>\n<joint name=\"j{i}\" type=\"revolute\"><parent link=\"l{}\"/><child link=\"l{i}\"/><origin xyz=\"0 0 0.1\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>\n",
            i - 1
        ));
    }
    urdf.push_str("</robot>");
    urdf
}

fn loading(c: &mut Criterion) {
    let mut g = c.benchmark_group("loading");
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(1));
    for n in [20_000, 100_000] {
        let urdf = chain(n);
        g.bench_function(format!("urdf_chain/{n}"), |b| {
            b.iter(|| {
                model_from_urdf_str(black_box(&urdf), "chain.urdf", &LoadOptions::default())
                    .unwrap()
            })
        });
    }
    let columns: Vec<String> = (0..1_000_000).map(|i| format!("c{i}")).collect();
    let csv = format!(
        "{}\n{}\n",
        columns.join(","),
        vec!["0"; columns.len()].join(",")
    );
    g.bench_function("csv_header/1000000", |b| {
        b.iter(|| Table::parse("wide.csv", black_box(&csv)).unwrap())
    });
    // a realistic log: 60 s at 1 kHz of a 7-joint arm (t, q, qd, qdd, tau)
    let mut log = String::from("t");
    for p in ["q", "qd", "qdd", "tau"] {
        for j in 1..=7 {
            log.push_str(&format!(",{p}{j}"));
        }
    }
    log.push('\n');
    for k in 0..60_000 {
        log.push_str(&format!("{}", k as f64 * 1e-3));
        for c in 0..28 {
            log.push_str(&format!(
                ",{}",
                ((k * 31 + c * 7) % 1000) as f64 * 0.001_234_567
            ));
        }
        log.push('\n');
    }
    g.bench_function("csv_log/60000x29", |b| {
        b.iter(|| Table::parse("log.csv", black_box(&log)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, loading);
criterion_main!(benches);
