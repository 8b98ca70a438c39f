//! Ctrl-C during a batch on the calling thread (below `parallel::PARALLEL_BATCH` samples): the
//! engine checks for it between its blocks. In a process of its own, since an interrupt is
//! asked for process-wide.

use perturbid_rs::{interrupt, parallel, robots, ErrorKind, Gravity, States};

#[test]
fn a_batch_on_the_calling_thread_stops_between_its_blocks() {
    let model = robots::builtin("a465").unwrap();
    let n = model.nv;
    let p = 10 * model.nbodies();
    let k = 2000;
    assert!(k < parallel::PARALLEL_BATCH);
    let q: Vec<f64> = (0..k * n).map(|i| (i % 17) as f64 * 0.1 - 0.8).collect();
    let states = States::new(n, &q, Some(&q), Some(&q)).unwrap();
    let mut ws = parallel::Workspace::new(&model);
    let mut out = vec![0.0; k * n * p];
    // asked for before the call: the first block is computed, the rest is not
    interrupt::request();
    let e = parallel::regressor(&model, &mut ws, &states, Gravity::Included, &mut out).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Interrupted, "{e}");
    assert!(e.to_string().contains("regressor"), "{e}");
    assert!(
        out[(k - 1) * n * p..].iter().all(|v| *v == 0.0),
        "the last sample untouched"
    );
    // a call that fits in one block finishes whatever was asked
    let one = States::new(n, &q[..n], Some(&q[..n]), Some(&q[..n])).unwrap();
    parallel::regressor(&model, &mut ws, &one, Gravity::Included, &mut out[..n * p]).unwrap();
    // once the interrupt is forgotten (a new piece of work), the batch runs whole
    interrupt::reset();
    parallel::regressor(&model, &mut ws, &states, Gravity::Included, &mut out).unwrap();
    assert!(out[(k - 1) * n * p..].iter().any(|v| *v != 0.0));
}
