//! `merge_sim`: run, compare and inspect cooperative merge simulations.
//!
//! Exit codes: 0 success, 1 the simulation or an output failed, 2 bad input (arguments,
//! scenario values, presets) — reported with the offending value, before anything is written.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, anyhow};
use clap::{Args, Parser, Subcommand, ValueEnum};
use mergesim::output::{check_output_path, write_atomically};
use mergesim::summary::RunSummary;
use mergesim::sweep::planner_label;
use planner::{ParameterSet, PlannerKind};
use scenarios::Scenario;
use sim::recording::Recorder;
use sim::{RunOptions, RunOutcome, TimeSeriesRow, World};
use vehicles::maneuver::{ManeuverConfig, ManeuverKind, run_maneuver};

/// `print!` that ends the process quietly when stdout is closed (output piped into `head`)
/// instead of panicking.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = write!(std::io::stdout(), $($arg)*) {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                std::process::exit(0);
            }
        }
    }};
}

/// `println!` with the same treatment of a closed stdout as [`out!`].
macro_rules! outln {
    ($($arg:tt)*) => {{
        out!($($arg)*);
        out!("\n");
    }};
}

/// Cooperative merge simulator: potential-field planners with interactive speed optimisation
/// (Lin et al.) on physics-based Rapier vehicles.
///
/// With no subcommand, `merge_sim` runs the paper's urgent merge with PF-ISO, prints a summary
/// table and writes a Rerun recording (urgent_merge_pf-iso.rrd) in the current folder.
#[derive(Parser, Debug)]
#[command(name = "merge_sim", version, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run one scenario closed-loop (the default).
    Run(RunArgs),
    /// Run every planner on one scenario and print them side by side.
    Compare(CompareArgs),
    /// Open-loop vehicle-dynamics tests on a flat pad (no planner).
    Maneuver(ManeuverArgs),
    /// List or print the built-in scenarios.
    #[command(subcommand)]
    Scenario(ScenarioCommand),
    /// Seeded Monte-Carlo sweep: N randomised instances in parallel, collision / near-miss
    /// statistics (instance i runs with seed SplitMix64::derive(--seed, i); replay it alone with
    /// `merge_sim run --scenario S --planner P --seed <that seed>`).
    Sweep(SweepArgs),
    /// Combine the --json files of the shards of one sweep into the aggregate of the whole sweep.
    MergeResults(MergeResultsArgs),
    /// Sensitivity grid: every planner on the same instances under {obstacles predicted in
    /// Eq. 7 on/off} × {sub-steps on/off} × path time gap τ × interaction time gap τ_I, with
    /// paired differences against the first planner.
    Grid(GridArgs),
}

#[derive(Args, Debug, Clone)]
struct RunArgs {
    /// Built-in scenario name or path to a scenario TOML file.
    #[arg(long, default_value = "urgent_merge", value_name = "NAME|PATH")]
    scenario: String,
    /// Planner of every planner-driven vehicle (overrides the scenario's choice).
    #[arg(long, value_name = "PLANNER", value_parser = parse_planner)]
    planner: Option<PlannerKind>,
    /// Planner parameter set: `paper` (the paper's literal reading) or `mergesim` (our
    /// improvements) [default: the scenario's `params`, else mergesim]. The scenario's
    /// [sim.planner] values apply on top of it.
    #[arg(long, value_name = "SET", value_parser = parse_params)]
    params: Option<ParameterSet>,
    /// Run the scenario instance drawn with seed N from its [randomise] ranges (N also seeds
    /// the V2V drops); a sweep's per-run rows give each run's seed. Without it the nominal
    /// scenario runs.
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
    /// Where to write the Rerun recording [default: <scenario>_<planner>.rrd].
    #[arg(long, value_name = "PATH", conflicts_with = "no_rrd")]
    rrd: Option<PathBuf>,
    /// Do not write a Rerun recording.
    #[arg(long)]
    no_rrd: bool,
    /// Open the recording in the Rerun viewer afterwards (needs `rerun` on PATH).
    #[arg(long, conflicts_with = "no_rrd")]
    view: bool,
    /// Write the JSON summary here.
    #[arg(long, value_name = "PATH")]
    json: Option<PathBuf>,
    /// Write the time series (one row per vehicle per logged instant) here.
    #[arg(long, value_name = "PATH")]
    csv: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Args, Debug)]
struct CompareArgs {
    /// Built-in scenario name or path to a scenario TOML file.
    #[arg(long, default_value = "urgent_merge", value_name = "NAME|PATH")]
    scenario: String,
    /// Planners to compare, comma-separated.
    #[arg(long, value_delimiter = ',', value_parser = parse_planner,
          default_value = "pf-cs,pf-sp,pf-iso,pf-iso-pred")]
    planners: Vec<PlannerKind>,
    /// Planner parameter set: `paper` (the paper's literal reading) or `mergesim` (our
    /// improvements) [default: the scenario's `params`, else mergesim]. The scenario's
    /// [sim.planner] values apply on top of it.
    #[arg(long, value_name = "SET", value_parser = parse_params)]
    params: Option<ParameterSet>,

    /// Compare on the scenario instance drawn with seed N (as `run --seed N`); without it the
    /// nominal scenario.
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
    /// Write the JSON summaries (an array) here.
    #[arg(long, value_name = "PATH")]
    json: Option<PathBuf>,
    /// Write figures into this existing folder: paths.png (both vehicles' paths per planner,
    /// the paper's Fig. 3), states_<vehicle>.png (sideslip, yaw, yaw rate, speed over time per
    /// planner; states_obstacle.png is the paper's Fig. 4) and time_series.csv (their data).
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
}

#[derive(Copy, Clone, Debug, ValueEnum)]
enum ManeuverName {
    /// Hold --speed-mps with the speed PID at fixed --steer-rad; report the settled state.
    SteadyState,
    /// Step the steering to --steer-rad at --speed-mps; report the response.
    StepSteer,
    /// Full braking from --speed-mps to standstill; report the stopping distance.
    Braking,
}

#[derive(Args, Debug)]
struct ManeuverArgs {
    /// Which test.
    maneuver: ManeuverName,
    /// Vehicle preset: bmw_320i, ford_escort, vw_vanagon.
    #[arg(long, default_value = "bmw_320i")]
    vehicle: String,
    /// Tire–road friction coefficient μ (> 0).
    #[arg(long, default_value_t = 0.8, allow_negative_numbers = true)]
    mu: f64,
    /// Speed (m/s).
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    speed_mps: f64,
    /// Front wheel steering angle (rad).
    #[arg(long, default_value_t = 0.02, allow_negative_numbers = true)]
    steer_rad: f64,
    /// Physics step (s).
    #[arg(long, default_value_t = 0.002, allow_negative_numbers = true)]
    dt_s: f64,
    /// Write the report as JSON here.
    #[arg(long, value_name = "PATH")]
    json: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
enum ScenarioCommand {
    /// List the built-in scenarios.
    List,
    /// Print a built-in scenario as TOML (which `--scenario PATH` reads back unchanged).
    Show {
        /// Built-in name.
        name: String,
    },
}

fn parse_planner(text: &str) -> Result<PlannerKind, String> {
    text.parse::<PlannerKind>().map_err(|e| e.to_string())
}

fn parse_params(text: &str) -> Result<ParameterSet, String> {
    text.parse::<ParameterSet>().map_err(|e| e.to_string())
}

/// Loads a scenario and switches it to `params` if given.
fn load_scenario(name_or_path: &str, params: Option<ParameterSet>) -> Result<Scenario, Failure> {
    let scenario = Scenario::load(name_or_path).map_err(input)?;
    match params {
        Some(set) => scenario.with_parameter_set(set).map_err(input),
        None => Ok(scenario),
    }
}

/// An error with its exit code: 2 for bad input, 1 for failures while running.
enum Failure {
    Input(anyhow::Error),
    Run(anyhow::Error),
}

fn input<E: Into<anyhow::Error>>(e: E) -> Failure {
    Failure::Input(e.into())
}

fn run_failure<E: Into<anyhow::Error>>(e: E) -> Failure {
    Failure::Run(e.into())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => cmd_run(&cli.run),
        Some(Command::Run(args)) => cmd_run(&args),
        Some(Command::Compare(args)) => cmd_compare(&args),
        Some(Command::Maneuver(args)) => cmd_maneuver(&args),
        Some(Command::Scenario(cmd)) => cmd_scenario(&cmd),
        Some(Command::Sweep(args)) => cmd_sweep(&args),
        Some(Command::MergeResults(args)) => cmd_merge_results(&args),
        Some(Command::Grid(args)) => cmd_grid(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
        Err(Failure::Run(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn progress_printer(enabled: bool, label: String) -> impl FnMut(f64) {
    let mut last = -1i64;
    move |fraction: f64| {
        if !enabled {
            return;
        }
        let percent = (fraction * 100.0).floor() as i64;
        if percent != last {
            last = percent;
            eprint!("\r{label}: {percent:3}%");
            if percent >= 100 {
                eprintln!();
            }
        }
    }
}

struct Finished {
    summary: RunSummary,
    outcome: RunOutcome,
}

fn simulate(
    scenario: &Scenario,
    planner: Option<PlannerKind>,
    seed: Option<u64>,
    rrd: Option<&Path>,
    keep_time_series: bool,
    show_progress: bool,
) -> Result<Finished, Failure> {
    let label = planner_label(scenario, planner);
    let recorder = match rrd {
        Some(path) => Recorder::new_file(path, "mergesim")
            .with_context(|| format!("cannot create recording {}", path.display()))
            .map_err(run_failure)?,
        None => Recorder::disabled(),
    };
    let options = RunOptions {
        planner_override: planner,
        seed: seed.unwrap_or(0),
        keep_time_series,
    };
    // With a seed, the instance drawn from the scenario's [randomise] ranges (as a sweep runs it).
    let instance = scenario.instance(seed);
    let world = World::new(instance.sim, &instance.vehicles, &options, recorder).map_err(input)?;
    let started = Instant::now();
    let progress = progress_printer(show_progress, format!("{} {label}", scenario.name));
    let outcome = world.run(progress).map_err(run_failure)?;
    let wall_time_s = started.elapsed().as_secs_f64();
    let summary = RunSummary::new(
        &scenario.name,
        scenario.params,
        &label,
        seed,
        wall_time_s,
        &outcome,
    );
    Ok(Finished { summary, outcome })
}

fn cmd_run(args: &RunArgs) -> Result<(), Failure> {
    let scenario = load_scenario(&args.scenario, args.params)?;
    let label = planner_label(&scenario, args.planner);
    let rrd = if args.no_rrd {
        None
    } else {
        Some(
            args.rrd
                .clone()
                .unwrap_or_else(|| PathBuf::from(format!("{}_{label}.rrd", scenario.name))),
        )
    };
    for (path, what) in [
        (rrd.as_deref(), "--rrd"),
        (args.json.as_deref(), "--json"),
        (args.csv.as_deref(), "--csv"),
    ] {
        if let Some(path) = path {
            check_output_path(path, what).map_err(|e| input(anyhow!(e)))?;
        }
    }
    let show_progress = !args.quiet && std::io::stderr().is_terminal();
    let finished = simulate(
        &scenario,
        args.planner,
        args.seed,
        rrd.as_deref(),
        args.csv.is_some(),
        show_progress,
    )?;
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&finished.summary).map_err(run_failure)?;
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))
            .map_err(run_failure)?;
    }
    if let Some(path) = &args.csv {
        let mut text = String::from(TimeSeriesRow::CSV_HEADER);
        text.push('\n');
        for row in &finished.outcome.time_series {
            text.push_str(&row.csv_line());
            text.push('\n');
        }
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))
            .map_err(run_failure)?;
    }
    if !args.quiet {
        out!("{}", finished.summary.table());
        for event in &finished.summary.events {
            outln!("event: {event}");
        }
        if let Some(path) = &rrd {
            outln!(
                "recording: {} (open with `rerun {}`)",
                path.display(),
                path.display()
            );
        }
    }
    if args.view
        && let Some(path) = &rrd
    {
        std::process::Command::new("rerun")
            .arg(path)
            .spawn()
            .context(
                "cannot start the Rerun viewer `rerun` (install: pip install rerun-sdk==0.36.3)",
            )
            .map_err(run_failure)?;
    }
    Ok(())
}

fn cmd_compare(args: &CompareArgs) -> Result<(), Failure> {
    let scenario = load_scenario(&args.scenario, args.params)?;
    if let Some(path) = &args.json {
        check_output_path(path, "--json").map_err(|e| input(anyhow!(e)))?;
    }
    if let Some(dir) = &args.plots {
        mergesim::plots::check_plot_dir(dir).map_err(|e| input(anyhow!(e)))?;
    }
    let show_progress = std::io::stderr().is_terminal();
    let mut summaries = Vec::new();
    let mut time_series = Vec::new();
    for &kind in &args.planners {
        let finished = simulate(
            &scenario,
            Some(kind),
            args.seed,
            None,
            args.plots.is_some(),
            show_progress,
        )?;
        summaries.push(finished.summary);
        time_series.push(finished.outcome.time_series);
    }
    out!("{}", comparison_table(&summaries));
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&summaries).map_err(run_failure)?;
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))
            .map_err(run_failure)?;
    }
    if let Some(dir) = &args.plots {
        let series: Vec<mergesim::plots::PlannerSeries<'_>> = summaries
            .iter()
            .zip(&time_series)
            .map(|(s, rows)| mergesim::plots::PlannerSeries {
                planner: &s.planner,
                rows,
            })
            .collect();
        let road = &scenario.instance(args.seed).sim.road;
        let written = mergesim::plots::write_comparison(
            dir,
            road,
            &series,
            mergesim::plots::FigureSize::default(),
        )
        .map_err(run_failure)?;
        for path in written {
            outln!("wrote {}", path.display());
        }
    }
    Ok(())
}

fn comparison_table(summaries: &[RunSummary]) -> String {
    let mut out = String::new();
    out.push_str(&format!("{:<28}", "metric"));
    for s in summaries {
        out.push_str(&format!("{:>13}", s.planner));
    }
    out.push('\n');
    let mut row = |label: &str, value: &dyn Fn(&RunSummary) -> String| {
        out.push_str(&format!("{label:<28}"));
        for s in summaries {
            out.push_str(&format!("{:>13}", value(s)));
        }
        out.push('\n');
    };
    row("collisions", &|s| s.collisions.to_string());
    row("min gap m", &|s| {
        s.min_gap_m
            .map(|g| format!("{g:.2}"))
            .unwrap_or_else(|| "-".into())
    });
    row("min TTC s", &|s| {
        s.min_ttc_s
            .map(|t| format!("{t:.2}"))
            .unwrap_or_else(|| "-".into())
    });
    row("near miss", &|s| s.near_miss.to_string());
    row("fallbacks", &|s| s.planner_stats.fallbacks.to_string());
    let names: Vec<String> = summaries
        .first()
        .map(|s| s.vehicles.iter().map(|v| v.id.clone()).collect())
        .unwrap_or_default();
    for (i, name) in names.iter().enumerate() {
        let get = |s: &RunSummary| s.vehicles.get(i).cloned();
        row(&format!("{name} |β|max rad"), &|s| {
            get(s)
                .map(|v| format!("{:.4}", v.max_abs_sideslip_rad))
                .unwrap_or_default()
        });
        row(&format!("{name} |ψ|max rad"), &|s| {
            get(s)
                .map(|v| format!("{:.4}", v.max_abs_yaw_rad))
                .unwrap_or_default()
        });
        row(&format!("{name} |r|max rad/s"), &|s| {
            get(s)
                .map(|v| format!("{:.4}", v.max_abs_yaw_rate_radps))
                .unwrap_or_default()
        });
        row(&format!("{name} v_min m/s"), &|s| {
            get(s)
                .map(|v| format!("{:.2}", v.min_speed_mps))
                .unwrap_or_default()
        });
        row(&format!("{name} path m"), &|s| {
            get(s)
                .map(|v| format!("{:.1}", v.path_length_m))
                .unwrap_or_default()
        });
        row(&format!("{name} r sign changes"), &|s| {
            get(s)
                .map(|v| v.yaw_rate_sign_changes.to_string())
                .unwrap_or_default()
        });
        let paper = |s: &RunSummary| get(s).and_then(|v| v.paper_metrics);
        let opt = |value: Option<f64>, digits: usize| {
            value
                .map(|x| format!("{x:.digits$}"))
                .unwrap_or_else(|| "-".into())
        };
        row(&format!("{name} slowing onset s"), &|s| {
            opt(paper(s).and_then(|p| p.slowing_onset_s), 2)
        });
        row(&format!("{name} RMS r merge zone"), &|s| {
            opt(paper(s).and_then(|p| p.merge_zone_rms_yaw_rate_radps), 4)
        });
        row(&format!("{name} RMS r outside"), &|s| {
            opt(
                paper(s).and_then(|p| p.outside_merge_zone_rms_yaw_rate_radps),
                4,
            )
        });
        row(&format!("{name} max lane offset m"), &|s| {
            opt(paper(s).map(|p| p.max_abs_lane_offset_m), 2)
        });
        row(&format!("{name} crosses divider x m"), &|s| {
            opt(paper(s).and_then(|p| p.divider_crossing).map(|c| c.x_m), 1)
        });
    }
    out
}

fn cmd_maneuver(args: &ManeuverArgs) -> Result<(), Failure> {
    if let Some(path) = &args.json {
        check_output_path(path, "--json").map_err(|e| input(anyhow!(e)))?;
    }
    let kind = match args.maneuver {
        ManeuverName::SteadyState => ManeuverKind::SteadyState,
        ManeuverName::StepSteer => ManeuverKind::StepSteer,
        ManeuverName::Braking => ManeuverKind::Braking,
    };
    let config = ManeuverConfig {
        kind,
        vehicle: args.vehicle.clone(),
        speed_mps: args.speed_mps,
        steer_rad: args.steer_rad,
        mu: args.mu,
        dt_s: args.dt_s,
        ..ManeuverConfig::default()
    };
    config.validate().map_err(input)?;
    let report = run_maneuver(&config).map_err(run_failure)?;
    let text = serde_json::to_string_pretty(&report).map_err(run_failure)?;
    if let Some(path) = &args.json {
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))
            .map_err(run_failure)?;
    }
    outln!("{text}");
    Ok(())
}

fn cmd_scenario(cmd: &ScenarioCommand) -> Result<(), Failure> {
    match cmd {
        ScenarioCommand::List => {
            for name in scenarios::builtin::names() {
                let scenario = Scenario::load(name).map_err(run_failure)?;
                outln!("{name:<20} {}", scenario.description);
            }
        }
        ScenarioCommand::Show { name } => {
            let text = scenarios::builtin::toml_of(name).ok_or_else(|| {
                input(anyhow!(
                    "unknown built-in scenario {name:?} (built-ins: {})",
                    scenarios::builtin::names().join(", ")
                ))
            })?;
            out!("{text}");
        }
    }
    Ok(())
}

#[derive(Args, Debug)]
struct SweepArgs {
    /// Built-in scenario name or path to a scenario TOML file.
    #[arg(long, default_value = "urgent_merge", value_name = "NAME|PATH")]
    scenario: String,
    /// Planner of every planner-driven vehicle (overrides the scenario's choice).
    #[arg(long, value_name = "PLANNER", value_parser = parse_planner)]
    planner: Option<PlannerKind>,
    /// Planner parameter set: `paper` (the paper's literal reading) or `mergesim` (our
    /// improvements) [default: the scenario's `params`, else mergesim]. The scenario's
    /// [sim.planner] values apply on top of it.
    #[arg(long, value_name = "SET", value_parser = parse_params)]
    params: Option<ParameterSet>,
    /// Number of randomised instances in the whole sweep (at least 1).
    #[arg(long, value_name = "N", value_parser = parse_runs)]
    runs: u64,
    /// Sweep seed K: instance i runs with seed SplitMix64::derive(K, i), which `run --seed`
    /// replays.
    #[arg(long, value_name = "K", default_value_t = 0)]
    seed: u64,
    /// Run only shard i of n (0-based): instances [⌊i·N/n⌋, ⌊(i+1)·N/n⌋). Default: from a Slurm
    /// job array (SLURM_ARRAY_TASK_ID, SLURM_ARRAY_TASK_COUNT), a Kubernetes Indexed Job
    /// (JOB_COMPLETION_INDEX with MERGESIM_SHARD_COUNT), else the whole sweep (0/1).
    #[arg(long, value_name = "i/n", value_parser = parse_shard)]
    shard: Option<mergesim::sweep::Shard>,
    /// Write the aggregate JSON here (with per-run samples, so shards can be merged).
    #[arg(long, value_name = "PATH")]
    json: Option<PathBuf>,
    /// Write one JSON line per run here (instance, seed, status, figures, wall time).
    #[arg(long, value_name = "PATH")]
    jsonl: Option<PathBuf>,
    /// Worker threads [default: one per core].
    #[arg(long, value_name = "N", value_parser = parse_threads)]
    threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Args, Debug)]
struct MergeResultsArgs {
    /// The `sweep --json` files of every shard of one sweep, in any order.
    #[arg(required = true, value_name = "SHARD_JSON")]
    inputs: Vec<PathBuf>,
    /// Write the aggregate of the whole sweep here.
    #[arg(long, value_name = "PATH")]
    json: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

fn parse_runs(text: &str) -> Result<u64, String> {
    match text.parse::<u64>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(n) => Ok(n),
        Err(_) => Err("expected a whole number of runs, at least 1".into()),
    }
}

fn parse_threads(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(0) | Err(_) => Err("expected a whole number of threads, at least 1".into()),
        Ok(n) => Ok(n),
    }
}

fn parse_shard(text: &str) -> Result<mergesim::sweep::Shard, String> {
    text.parse()
        .map_err(|e: mergesim::sweep::ShardError| e.to_string())
}

fn sweep_failure(e: mergesim::sweep::SweepError) -> Failure {
    match e {
        mergesim::sweep::SweepError::Invalid(_) => input(e),
        mergesim::sweep::SweepError::Threads(_) => run_failure(e),
    }
}

fn write_output(path: &Path, text: &str) -> Result<(), Failure> {
    write_atomically(path, text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
        .map_err(run_failure)
}

fn cmd_sweep(args: &SweepArgs) -> Result<(), Failure> {
    use mergesim::sweep::{Shard, SweepOptions, SweepPlan, run_sweep};
    let scenario = load_scenario(&args.scenario, args.params)?;
    for (path, what) in [
        (args.json.as_deref(), "--json"),
        (args.jsonl.as_deref(), "--jsonl"),
    ] {
        if let Some(path) = path {
            check_output_path(path, what).map_err(|e| input(anyhow!(e)))?;
        }
    }
    let shard = match args.shard {
        Some(shard) => shard,
        None => Shard::from_environment(|name| std::env::var(name).ok())
            .map_err(input)?
            .unwrap_or(Shard::WHOLE),
    };
    let plan = SweepPlan {
        scenario,
        planner: args.planner,
        runs: args.runs,
        seed: args.seed,
        shard,
    };
    let instances = shard.instances(args.runs);
    let bar = if !args.quiet && std::io::stderr().is_terminal() {
        let bar = indicatif::ProgressBar::new(instances.end - instances.start);
        let style = indicatif::ProgressStyle::with_template(
            "{msg} [{bar:30}] {pos}/{len} runs, {per_sec}, ETA {eta}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
        bar.set_style(style);
        bar.set_message(format!("sweep {} shard {shard}", plan.scenario.name));
        bar
    } else {
        indicatif::ProgressBar::hidden()
    };
    let options = SweepOptions {
        threads: args.threads,
    };
    let outcome = run_sweep(&plan, &options, &|| bar.inc(1)).map_err(sweep_failure)?;
    bar.finish_and_clear();
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&outcome.summary).map_err(run_failure)?;
        write_output(path, &text)?;
    }
    if let Some(path) = &args.jsonl {
        let text = outcome
            .summary
            .jsonl(&outcome.run_wall_times_s)
            .map_err(run_failure)?;
        write_output(path, &text)?;
    }
    if !args.quiet {
        out!("{}", outcome.summary.table());
        for row in outcome.summary.samples.iter().filter(|r| r.error.is_some()) {
            outln!(
                "run {} (seed {}) {:?}: {}",
                row.instance,
                row.seed,
                row.status,
                row.error.as_deref().unwrap_or_default()
            );
        }
    }
    Ok(())
}

fn cmd_merge_results(args: &MergeResultsArgs) -> Result<(), Failure> {
    use mergesim::sweep::{SweepSummary, merge_shards};
    if let Some(path) = &args.json {
        check_output_path(path, "--json").map_err(|e| input(anyhow!(e)))?;
    }
    let mut parts = Vec::with_capacity(args.inputs.len());
    for path in &args.inputs {
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {origin}"))
            .map_err(input)?;
        let part: SweepSummary = serde_json::from_str(&text)
            .with_context(|| format!("{origin}: not a `merge_sim sweep --json` file"))
            .map_err(input)?;
        parts.push((origin, part));
    }
    let merged = merge_shards(parts).map_err(sweep_failure)?;
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&merged).map_err(run_failure)?;
        write_output(path, &text)?;
    }
    if !args.quiet {
        out!("{}", merged.table());
    }
    Ok(())
}

#[derive(Args, Debug)]
struct GridArgs {
    /// Built-in scenario name or path to a scenario TOML file.
    #[arg(long, default_value = "urgent_merge", value_name = "NAME|PATH")]
    scenario: String,
    /// Base parameter set of every cell (the four grid parameters are set on top of it).
    #[arg(long, value_name = "SET", value_parser = parse_params)]
    params: Option<ParameterSet>,
    /// Planners, comma-separated; the first is the reference of the paired differences.
    #[arg(long, value_delimiter = ',', value_parser = parse_planner,
          default_value = "pf-cs,pf-sp,pf-iso,pf-iso-pred")]
    planners: Vec<PlannerKind>,
    /// Path-field time gaps τ (s), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "0,1,2,3", value_parser = parse_gap)]
    path_gaps: Vec<f64>,
    /// Interaction time gaps τ_I (s), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2,3", value_parser = parse_gap)]
    interaction_gaps: Vec<f64>,
    /// Run only the parameter set's own cell (its prediction, sub-steps, τ and τ_I): a paired
    /// study of the planners as configured, with a table of paired differences for every
    /// vehicle and figure.
    #[arg(long, conflicts_with_all = ["path_gaps", "interaction_gaps"])]
    base_only: bool,
    /// Instances per cell: 0 runs the nominal scenario only; N runs the instances a sweep
    /// with --seed would (instance i with seed SplitMix64::derive(seed, i)).
    #[arg(long, default_value_t = 0, value_name = "N")]
    runs: u64,
    /// Sweep seed of the drawn instances.
    #[arg(long, default_value_t = 0, value_name = "K")]
    seed: u64,
    /// Vehicle whose figures the table and the figure compare.
    #[arg(long, default_value = "obstacle", value_name = "NAME")]
    vehicle: String,
    /// Write every run (one line per run and vehicle) here.
    #[arg(long, value_name = "PATH")]
    csv: Option<PathBuf>,
    /// Write the runs and the paired differences as JSON here.
    #[arg(long, value_name = "PATH")]
    json: Option<PathBuf>,
    /// Write the figure (heat maps of the mean ratio of the vehicle's peak yaw rate to the
    /// first planner's) here.
    #[arg(long, value_name = "PATH")]
    plot: Option<PathBuf>,
    /// Worker threads [default: one per core].
    #[arg(long, value_name = "N", value_parser = parse_threads)]
    threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(long, short)]
    quiet: bool,
}

fn parse_gap(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() && (0.0..=10.0).contains(&v) => Ok(v),
        _ => Err("expected a time gap in [0, 10] s".into()),
    }
}

/// Most instances a grid cell may run (the default grid runs 36 cells × planners of them).
const MAX_GRID_RUNS: u64 = 10_000;

fn cmd_grid(args: &GridArgs) -> Result<(), Failure> {
    use mergesim::grid::{GridAxes, GridMetric, GridPlan, job_count, run_grid};
    let scenario = load_scenario(&args.scenario, args.params)?;
    if !scenario.vehicles.iter().any(|v| v.name == args.vehicle) {
        return Err(input(anyhow!(
            "--vehicle {:?}: no such vehicle in scenario {} (vehicles: {})",
            args.vehicle,
            scenario.name,
            scenario
                .vehicles
                .iter()
                .map(|v| v.name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    if args.runs > MAX_GRID_RUNS {
        return Err(input(anyhow!(
            "--runs {}: at most {MAX_GRID_RUNS} instances per cell",
            args.runs
        )));
    }
    for (path, what) in [
        (args.csv.as_deref(), "--csv"),
        (args.json.as_deref(), "--json"),
        (args.plot.as_deref(), "--plot"),
    ] {
        if let Some(path) = path {
            check_output_path(path, what).map_err(|e| input(anyhow!(e)))?;
        }
    }
    if args.plot.is_some() && args.planners.len() < 2 {
        return Err(input(anyhow!(
            "--plot: the figure compares planners with the first; give at least two"
        )));
    }
    let axes = if args.base_only {
        GridAxes::of_params(&scenario.sim.planner)
    } else {
        GridAxes {
            path_time_gap_s: args.path_gaps.clone(),
            interaction_time_gap_s: args.interaction_gaps.clone(),
            ..GridAxes::default()
        }
    };
    let plan = GridPlan {
        axes,
        scenario,
        planners: args.planners.clone(),
        runs: args.runs,
        seed: args.seed,
        threads: args.threads,
    };
    let bar = if !args.quiet && std::io::stderr().is_terminal() {
        let bar = indicatif::ProgressBar::new(job_count(&plan));
        let style = indicatif::ProgressStyle::with_template(
            "{msg} [{bar:30}] {pos}/{len} runs, {per_sec}, ETA {eta}",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
        bar.set_style(style);
        bar.set_message(format!("grid {}", plan.scenario.name));
        bar
    } else {
        indicatif::ProgressBar::hidden()
    };
    let outcome = run_grid(&plan, &|| bar.inc(1)).map_err(|e| run_failure(anyhow!(e)))?;
    bar.finish_and_clear();
    let peak = outcome.paired_differences(&args.vehicle, GridMetric::PeakYawRate);
    let zone = outcome.paired_differences(&args.vehicle, GridMetric::MergeZoneRmsYawRate);
    if let Some(path) = &args.csv {
        write_output(path, &outcome.csv())?;
    }
    if let Some(path) = &args.json {
        let value = serde_json::json!({
            "grid": &outcome,
            "vehicle": &args.vehicle,
            "paired_peak_yaw_rate": &peak,
            "paired_merge_zone_rms_yaw_rate": &zone,
        });
        let text = serde_json::to_string_pretty(&value).map_err(run_failure)?;
        write_output(path, &text)?;
    }
    if let Some(path) = &args.plot {
        mergesim::grid_plot::write_grid_png(path, &outcome, &args.vehicle, GridMetric::PeakYawRate)
            .map_err(run_failure)?;
    }
    if !args.quiet {
        outln!(
            "grid {} ({} set), {} instance(s) per cell, vehicle {}: mean of each planner / mean of {} \
             (peak |r|; RMS r in the merge zone), collisions",
            outcome.scenario,
            outcome.params,
            outcome.runs.max(1),
            args.vehicle,
            outcome.planners[0]
        );
        let ratio = |d: &mergesim::grid::PairedDifference| match (d.mean, d.reference_mean) {
            (Some(a), Some(b)) if b > 0.0 => format!("{:.2}", a / b),
            _ => "-".into(),
        };
        for (p, z) in peak.iter().zip(&zone) {
            outln!(
                "{:<22} {:<12} peak {:>5}  zone {:>5}  collisions {} ({} {})",
                p.cell.label(),
                p.planner,
                ratio(p),
                ratio(z),
                p.collisions,
                p.reference,
                p.reference_collisions
            );
        }
        if outcome.axes.cells().len() == 1 {
            out!("{}", study_table(&outcome));
        }
        outln!("wall time {:.1} s", outcome.wall_time_s);
    }
    Ok(())
}

/// Paired differences of every planner against the first, for every vehicle and figure, and
/// the collisions of each planner (a single-cell grid).
fn study_table(outcome: &mergesim::grid::GridOutcome) -> String {
    use mergesim::grid::GridMetric;
    let mut out = String::new();
    let vehicles: Vec<String> = outcome
        .rows
        .iter()
        .flat_map(|r| r.vehicles.iter().map(|v| v.vehicle.clone()))
        .fold(Vec::new(), |mut acc, v| {
            if !acc.contains(&v) {
                acc.push(v);
            }
            acc
        });
    let reference = &outcome.planners[0];
    out.push_str(&format!(
        "paired differences against {reference} (mean ± standard error; n: pairs; lower: \
         instances where the planner's value is lower)\n"
    ));
    for planner in &outcome.planners {
        let rows: Vec<_> = outcome
            .rows
            .iter()
            .filter(|r| &r.planner == planner)
            .collect();
        let collisions: u64 = rows.iter().map(|r| r.collisions.unwrap_or(0)).sum();
        let colliding_runs = rows
            .iter()
            .filter(|r| r.collisions.unwrap_or(0) > 0)
            .count();
        let failed = rows.iter().filter(|r| r.error.is_some()).count();
        out.push_str(&format!(
            "{planner:<12} collisions {collisions} in {colliding_runs} of {} runs{}\n",
            rows.len(),
            if failed > 0 {
                format!(", {failed} failed")
            } else {
                String::new()
            }
        ));
    }
    for vehicle in &vehicles {
        for metric in GridMetric::ALL {
            for d in outcome.paired_differences(vehicle, metric) {
                let digits = metric.decimals();
                let fmt = |v: Option<f64>| {
                    v.map(|x| format!("{x:.digits$}"))
                        .unwrap_or_else(|| "-".into())
                };
                out.push_str(&format!(
                    "{vehicle:<10} {:<26} {:<12} {:>9} vs {:>9}  diff {:>9} ± {:<7} n {:>3} lower {:>3}\n",
                    metric.label(),
                    d.planner,
                    fmt(d.mean),
                    fmt(d.reference_mean),
                    fmt(d.mean_difference),
                    fmt(d.standard_error),
                    d.pairs,
                    d.lower
                ));
            }
        }
    }
    out
}
