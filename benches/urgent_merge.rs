//! Wall time of the default 25 s urgent merge (2 vehicles, PF-ISO, no recording).
//!
//! `cargo bench --bench urgent_merge`

use criterion::{Criterion, criterion_group, criterion_main};
use mergesim::experiment::{InstanceOptions, run_quietly};
use mergesim::scenarios::scenario::Scenario;

fn urgent_merge(c: &mut Criterion) {
    let scenario = match Scenario::load("urgent_merge") {
        Ok(s) => s,
        Err(e) => panic!("built-in scenario: {e}"),
    };
    let mut group = c.benchmark_group("closed_loop");
    group.sample_size(10);
    group.bench_function("urgent_merge_25s_pf_iso", |b| {
        b.iter(
            || match run_quietly(&scenario, &InstanceOptions::default()) {
                Ok(finished) => finished.outcome,
                Err(e) => panic!("run failed: {e}"),
            },
        )
    });
    group.finish();
}

criterion_group!(benches, urgent_merge);
criterion_main!(benches);
