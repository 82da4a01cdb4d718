//! The scaling curve of the README ("Performance"): the platoon of `platoon_merge_50` with 2,
//! 10, 25, 50 and 100 vehicles (`merge_sim scenario platoon --vehicles N`) and the two-vehicle
//! `urgent_merge`, each run unrecorded `--repeats` times (3; the run of median wall time
//! counts); prints the Markdown table (wall time, simulated vehicle-seconds, wall µs per
//! vehicle-second, the ratios, planner p50/p99) and writes the curve as a PNG.
//!
//! `cargo run --release --example scaling_curve -- --out docs/figures/scaling.png`
//!
//! 100 vehicles take about a minute per run on two cores; `--sizes 2,10 --repeats 1` is quick.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Parser;
use mergesim::scaling::{ScalingPoint, markdown_table, measure, write_png};
use mergesim::scenarios::platoon::platoon;
use mergesim::scenarios::scenario::Scenario;

#[derive(Parser, Debug)]
#[command(about = "Cost per simulated vehicle-second as the platoon grows")]
struct Args {
    /// Where to write the PNG.
    #[arg(long, value_name = "PATH", default_value = "docs/figures/scaling.png")]
    out: PathBuf,
    /// Also write the Markdown table here (it is printed in any case).
    #[arg(long, value_name = "PATH")]
    table: Option<PathBuf>,
    /// Platoon sizes, the first being the reference of the ratio column.
    #[arg(long, value_delimiter = ',', default_value = "2,10,25,50,100")]
    sizes: Vec<usize>,
    /// Runs per scenario; the one of median wall time counts.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
}

fn main() -> Result<()> {
    let args = Args::parse();
    if args.sizes.is_empty() {
        bail!("--sizes: at least one size");
    }
    let threads = rayon::current_num_threads();
    eprintln!("{threads} threads");
    let reference_scenario = Scenario::load("urgent_merge")?;
    let reference = run(&reference_scenario, args.repeats)?;
    let mut points: Vec<ScalingPoint> = Vec::new();
    for &n in &args.sizes {
        let scenario = platoon(n).with_context(|| format!("platoon of {n}"))?;
        points.push(run(&scenario, args.repeats)?);
    }
    let table = markdown_table(&points, &points[0], &reference);
    print!("{table}");
    if let Some(path) = &args.table {
        mergesim::output::write_atomically(path, table.as_bytes())
            .with_context(|| format!("{}", path.display()))?;
    }
    let caption = format!(
        "Wall time per simulated vehicle-second ({threads} threads, unrecorded, median of {})",
        args.repeats.max(1)
    );
    write_png(&args.out, &points, &reference, &caption)?;
    eprintln!("wrote {}", args.out.display());
    Ok(())
}

fn run(scenario: &Scenario, repeats: usize) -> Result<ScalingPoint> {
    let point = measure(scenario, repeats).with_context(|| scenario.name.clone())?;
    eprintln!(
        "{:<20} {:>4} vehicles  {:>8.2} s wall  {:>7.0} µs per vehicle-s  p50 {:.0} µs",
        point.scenario,
        point.vehicles,
        point.wall_time_s,
        point.us_per_vehicle_second(),
        point.planner_p50_us
    );
    Ok(point)
}
