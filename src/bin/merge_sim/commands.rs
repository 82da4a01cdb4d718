//! The subcommands: each parses nothing and prints or writes what the library returns.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow};
use mergesim::output::{check_distinct, check_output_path, write_atomically};
use mergesim::report::{
    comparison_json, comparison_markdown, comparison_table, grid_table, study_table,
    time_series_csv,
};
use mergesim::run_caption::RunCaption;
use scenarios::Scenario;
use vehicles::maneuver::{ManeuverConfig, ManeuverKind, run_maneuver};

use crate::args::{CompareArgs, GridArgs, ManeuverArgs, ManeuverName, RunArgs, ScenarioCommand};
use crate::signals::Interrupt;
use crate::{
    Failure, Simulation, input, interrupted, load_source, out, outln, run_failure, simulate,
    write_output,
};

/// Checks every output (path, option) before any work: each a writable regular file or new
/// (`check_output_path`), no two the same file, none of them one of `inputs`.
pub(crate) fn check_outputs(
    outputs: &[(Option<&Path>, &str)],
    inputs: &[&Path],
) -> Result<(), Failure> {
    let given: Vec<(&Path, &str)> = outputs
        .iter()
        .filter_map(|(path, what)| path.map(|p| (p, *what)))
        .collect();
    for (path, what) in &given {
        check_output_path(path, what).map_err(|e| input(anyhow!(e)))?;
    }
    check_distinct(&given, inputs).map_err(|e| input(anyhow!(e)))
}

/// The scenario file read by `--scenario` (none for a built-in).
pub(crate) fn scenario_file(name_or_path: &str) -> Vec<&Path> {
    if scenarios::builtin::toml_of(name_or_path).is_some() {
        Vec::new()
    } else {
        vec![Path::new(name_or_path)]
    }
}

/// A progress bar of `len` runs on a terminal (hidden when `quiet` or stderr is not one).
pub(crate) fn progress_bar(quiet: bool, len: u64, message: String) -> indicatif::ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    let style = indicatif::ProgressStyle::with_template(
        "{msg} [{bar:30}] {pos}/{len} runs, {per_sec}, ETA {eta}",
    )
    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
    bar.set_style(style);
    bar.set_message(message);
    bar
}

/// Recordings estimated above this size are announced before they are written.
const RECORDING_WARNING_BYTES: f64 = 500e6;

/// The default recording of a run: `<scenario>_<planner>.rrd`; on a CommonRoad road, with
/// `_<mode>` when its recorded traffic is not replayed (the default) and `_<duration>s` when
/// `--duration` is given, so that runs of one file in different modes do not overwrite each
/// other.
fn default_rrd(scenario: &Scenario, label: &str, duration_s: Option<f64>) -> PathBuf {
    use mergesim::output::file_name_part;
    let mut stem = format!(
        "{}_{}",
        file_name_part(&scenario.name),
        file_name_part(label)
    );
    if let Some(road) = scenario.sim.commonroad_road() {
        if road.recorded_traffic != sim::recorded_traffic::TrafficMode::Replay {
            stem.push_str(&format!("_{}", road.recorded_traffic));
        }
        if let Some(d) = duration_s {
            stem.push_str(&format!("_{}s", file_name_part(&d.to_string())));
        }
    }
    PathBuf::from(format!("{stem}.rrd"))
}

pub(crate) fn cmd_run(args: &RunArgs, interrupt: &Interrupt) -> Result<(), Failure> {
    let scenario = load_source(&args.source)?;
    let label = mergesim::sweep::planner_label(&scenario, args.planner.as_deref());
    if !cfg!(feature = "rerun") && (args.rrd.is_some() || args.view) {
        return Err(crate::input(anyhow::anyhow!(
            "{}",
            sim::recording::RecordingError::Unsupported
        )));
    }
    // Without Rerun support a run records nothing unless asked to (and then refuses, above).
    let rrd = if args.no_rrd || !cfg!(feature = "rerun") {
        None
    } else {
        Some(
            args.rrd
                .clone()
                .unwrap_or_else(|| default_rrd(&scenario, &label, args.source.duration)),
        )
    };
    check_outputs(
        &[
            (rrd.as_deref(), "--rrd"),
            (args.json.as_deref(), "--json"),
            (args.csv.as_deref(), "--csv"),
            (args.gif.as_deref(), "--gif"),
        ],
        &scenario_file(&args.source.scenario),
    )?;
    let follow = followed_vehicle(&scenario, args.follow.as_deref())?;
    let gif_params = mergesim::animation::GifParams {
        fps: args.gif_fps,
        width_px: args.gif_width,
        view: args.gif_view.map_or_else(
            || mergesim::animation::GifView::default_for(scenario.vehicles.len()),
            Into::into,
        ),
        lane_ids: args.lane_ids,
        ..mergesim::animation::GifParams::default()
    };
    if args.gif.is_some() {
        gif_params.validate().map_err(input)?;
    }
    let seed = args.instance_seed();
    if let Some(path) = &rrd {
        let instance = scenario.instance(seed);
        let bytes = sim::recording::size_estimate::estimated_bytes(
            &instance.sim,
            &instance.vehicles,
            args.record_detail.0,
        );
        if bytes > RECORDING_WARNING_BYTES {
            eprintln!(
                "warning: the recording {} will be about {:.0} MB ({} vehicles, {} s); \
                 --record-detail 2 (fields and received paths of fewer vehicles) or --no-rrd \
                 make it smaller",
                path.display(),
                bytes / 1e6,
                instance.vehicles.len(),
                instance.sim.duration_s
            );
        }
    }
    if let Some(seed) = seed
        && !args.quiet
    {
        // stderr: stdout stays the table it always was.
        eprint!(
            "{}",
            mergesim::sweep::describe_instance(&scenario, seed, args.sweep_seed.zip(args.instance))
        );
    }
    let show_progress = !args.quiet && std::io::stderr().is_terminal();
    let what = Simulation {
        planner: args.planner.as_deref(),
        seed,
        rrd: rrd.as_deref(),
        keep_time_series: args.csv.is_some() || args.gif.is_some(),
        show_progress,
        profile: args.profile,
        record_detail: args.record_detail.0,
        follow: Some(&follow),
        lane_ids: args.lane_ids,
    };
    let mut finished = simulate(&scenario, &what, interrupt)?;
    finished.summary = finished.summary.with_drawn(&scenario);
    if let Some(path) = &args.gif {
        let gif = GifRun {
            path,
            follow: &follow,
            params: &gif_params,
            show_progress,
        };
        write_run_gif(&gif, &scenario, args, &finished)?;
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&finished.summary).map_err(run_failure)?;
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))
            .map_err(run_failure)?;
    }
    if let Some(path) = &args.csv {
        let text = time_series_csv(&finished.outcome.time_series);
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))
            .map_err(run_failure)?;
    }
    if !args.quiet {
        out!("{}", finished.summary.table());
        for event in &finished.summary.events {
            outln!("event: {event}");
        }
        if let Some(profile) = &finished.summary.profile {
            out!("\nwhere the wall time went:\n{}", profile.table());
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

/// The vehicle `--follow` names (it must exist: exit 2 before any work), else `ego`, else the
/// scenario's first vehicle.
fn followed_vehicle(scenario: &Scenario, asked: Option<&str>) -> Result<String, Failure> {
    let names: Vec<&str> = scenario.vehicles.iter().map(|v| v.name.as_str()).collect();
    match asked {
        Some(name) if names.contains(&name) => Ok(name.to_string()),
        Some(name) => Err(input(anyhow!(
            "--follow: no vehicle named {name:?} in {} (vehicles: {})",
            scenario.name,
            names.join(", ")
        ))),
        None if names.contains(&"ego") => Ok("ego".into()),
        None => Ok(names
            .first()
            .map_or_else(|| "ego".into(), |n| n.to_string())),
    }
}

/// Where and how `--gif` is written.
struct GifRun<'a> {
    path: &'a Path,
    follow: &'a str,
    params: &'a mergesim::animation::GifParams,
    show_progress: bool,
}

/// Writes `--gif` from the run's time series and prints where it went.
fn write_run_gif(
    gif: &GifRun<'_>,
    scenario: &Scenario,
    args: &RunArgs,
    finished: &mergesim::experiment::Finished,
) -> Result<(), Failure> {
    let GifRun {
        path,
        follow,
        params,
        show_progress,
    } = *gif;
    use mergesim::animation::{GifVehicle, write_gif};
    let instance = scenario.instance(args.instance_seed());
    let mut vehicles = Vec::with_capacity(instance.vehicles.len());
    for (id, spec) in instance.vehicles.iter().enumerate() {
        let car = vehicles::VehicleParams::preset(&spec.preset).map_err(input)?;
        vehicles.push(GifVehicle {
            name: spec.name.clone(),
            id: u32::try_from(id).map_err(input)?,
            length_m: car.length_m,
            width_m: car.width_m,
        });
    }
    let title = format!("{} {}", finished.summary.scenario, finished.summary.planner);
    let started = std::time::Instant::now();
    let mut last_percent = -1i64;
    let progress = |fraction: f64| {
        let percent = (fraction * 100.0).floor() as i64;
        if show_progress && percent != last_percent {
            last_percent = percent;
            eprint!("\rgif: {percent:3}%");
            if percent >= 100 {
                eprintln!();
            }
        }
    };
    // The road as lanes (the world's own road: `World` builds its lanes the same way).
    let lanes = instance.sim.lanes().map_err(input)?;
    let stats = write_gif(
        path,
        &lanes,
        &vehicles,
        &finished.outcome.time_series,
        &finished.outcome.recorded_track,
        &finished.outcome.safety.collisions,
        follow,
        &title,
        params,
        progress,
    )
    .map_err(run_failure)?;
    if !args.quiet {
        outln!(
            "gif: {} ({} frames, {} x {} px, {:.2} MB, written in {:.1} s)",
            path.display(),
            stats.frames,
            stats.size_px.0,
            stats.size_px.1,
            stats.bytes as f64 / 1e6,
            started.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

pub(crate) fn cmd_compare(args: &CompareArgs, interrupt: &Interrupt) -> Result<(), Failure> {
    let scenario = load_source(&args.source)?;
    check_outputs(
        &[
            (args.json.as_deref(), "--json"),
            (args.markdown.as_deref(), "--markdown"),
        ],
        &scenario_file(&args.source.scenario),
    )?;
    let caption = RunCaption::of_scenario(&scenario, args.seed);
    if let Some(dir) = &args.plots {
        let vehicles: Vec<&str> = scenario.vehicles.iter().map(|v| v.name.as_str()).collect();
        mergesim::plots::check_plot_dir(dir, &vehicles).map_err(|e| input(anyhow!(e)))?;
    }
    let show_progress = std::io::stderr().is_terminal();
    let mut summaries = Vec::new();
    let mut time_series = Vec::new();
    let mut collisions = Vec::new();
    for name in &args.planners {
        let what = Simulation {
            planner: Some(name.as_str()),
            seed: args.seed,
            keep_time_series: args.plots.is_some(),
            show_progress,
            ..Simulation::default()
        };
        let finished = simulate(&scenario, &what, interrupt)?;
        summaries.push(finished.summary.with_drawn(&scenario));
        time_series.push(finished.outcome.time_series);
        collisions.push(finished.outcome.safety.collisions);
    }
    out!("{}", comparison_table(&caption, &summaries));
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&comparison_json(&caption, &summaries))
            .map_err(run_failure)?;
        write_atomically(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))
            .map_err(run_failure)?;
    }
    if let Some(path) = &args.markdown {
        write_atomically(path, comparison_markdown(&caption, &summaries).as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))
            .map_err(run_failure)?;
    }
    if let Some(dir) = &args.plots {
        let series: Vec<mergesim::plots::PlannerSeries<'_>> = summaries
            .iter()
            .zip(&time_series)
            .zip(&collisions)
            .map(|((s, rows), collisions)| mergesim::plots::PlannerSeries {
                planner: &s.planner,
                rows,
                collisions,
            })
            .collect();
        // The road as lanes, as the world builds it from the scenario's road.
        let lanes = scenario.instance(args.seed).sim.lanes().map_err(input)?;
        let written = mergesim::plots::write_comparison(
            dir,
            &lanes,
            args.lane_ids,
            &series,
            mergesim::plots::FigureSize::default(),
            &caption,
        )
        .map_err(run_failure)?;
        for path in written {
            outln!("wrote {}", path.display());
        }
    }
    Ok(())
}

pub(crate) fn cmd_maneuver(args: &ManeuverArgs) -> Result<(), Failure> {
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

pub(crate) fn cmd_scenario(cmd: &ScenarioCommand) -> Result<(), Failure> {
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
        ScenarioCommand::Platoon { vehicles } => {
            // Checked like a scenario file before it is printed.
            scenarios::platoon::platoon(*vehicles).map_err(|e| input(anyhow!(e)))?;
            out!("{}", scenarios::platoon::platoon_toml(*vehicles));
        }
    }
    Ok(())
}

/// The vehicle a grid compares: `--vehicle` if it names one of the scenario's, else (without
/// `--vehicle`) the one named `obstacle`, else the first not named `ego`, else the first.
fn grid_vehicle(scenario: &Scenario, asked: Option<&str>) -> Result<String, Failure> {
    let names: Vec<&str> = scenario.vehicles.iter().map(|v| v.name.as_str()).collect();
    let chosen = match asked {
        Some(name) => names.iter().find(|n| **n == name),
        None => names
            .iter()
            .find(|n| **n == "obstacle")
            .or_else(|| names.iter().find(|n| **n != "ego"))
            .or_else(|| names.first()),
    };
    chosen.map(|n| n.to_string()).ok_or_else(|| {
        input(anyhow!(
            "--vehicle {:?}: no such vehicle in scenario {} (vehicles: {})",
            asked.unwrap_or_default(),
            scenario.name,
            names.join(", ")
        ))
    })
}

pub(crate) fn cmd_grid(args: &GridArgs, interrupt: &Interrupt) -> Result<(), Failure> {
    use mergesim::grid::{GridAxes, GridMetric, GridPlan, MAX_GRID_RUNS, job_count, run_grid};
    let scenario = load_source(&args.source)?;
    let vehicle = grid_vehicle(&scenario, args.vehicle.as_deref())?;
    if args.runs > MAX_GRID_RUNS {
        return Err(input(anyhow!(
            "--runs {}: at most {MAX_GRID_RUNS} instances per cell",
            args.runs
        )));
    }
    check_outputs(
        &[
            (args.csv.as_deref(), "--csv"),
            (args.json.as_deref(), "--json"),
            (args.plot.as_deref(), "--plot"),
        ],
        &scenario_file(&args.source.scenario),
    )?;
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
    let caption = RunCaption::of_scenario(&scenario, None);
    let plan = GridPlan {
        axes,
        scenario,
        planners: args.planners.clone(),
        registry: std::sync::Arc::new(sim::BehaviourRegistry::builtin()),
        runs: args.runs,
        seed: args.seed,
        threads: args.threads,
        interrupt: Some(interrupt.flag.clone()),
    };
    let bar = progress_bar(
        args.quiet,
        job_count(&plan),
        format!("grid {}", plan.scenario.name),
    );
    let outcome = run_grid(&plan, &|| bar.inc(1));
    if interrupt.raised() {
        bar.finish_and_clear();
        return Err(interrupted(interrupt, "grid stopped; nothing written"));
    }
    let outcome = outcome.map_err(|e| run_failure(anyhow!(e)))?;
    bar.finish_and_clear();
    let peak = outcome.paired_differences(&vehicle, GridMetric::PeakYawRate);
    let zone = outcome.paired_differences(&vehicle, GridMetric::MergeZoneRmsYawRate);
    if let Some(path) = &args.csv {
        write_output(path, &outcome.csv())?;
    }
    if let Some(path) = &args.json {
        let value = serde_json::json!({
            "grid": &outcome,
            "vehicle": &vehicle,
            "paired_peak_yaw_rate": &peak,
            "paired_merge_zone_rms_yaw_rate": &zone,
        });
        let text = serde_json::to_string_pretty(&value).map_err(run_failure)?;
        write_output(path, &text)?;
    }
    if let Some(path) = &args.plot {
        mergesim::grid_plot::write_grid_png(
            path,
            &outcome,
            &vehicle,
            GridMetric::PeakYawRate,
            &caption,
        )
        .map_err(run_failure)?;
    }
    if !args.quiet {
        out!("{}", grid_table(&outcome, &vehicle));
        if outcome.axes.cells().len() == 1 {
            out!("{}", study_table(&outcome));
        }
        outln!("wall time {:.1} s", outcome.wall_time_s);
    }
    Ok(())
}

pub(crate) fn cmd_limits() -> Result<(), Failure> {
    out!("{}", mergesim::limits::markdown());
    Ok(())
}
