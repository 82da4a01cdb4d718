//! The subcommands: each parses nothing and prints or writes what the library returns.

use std::io::IsTerminal;
use std::path::Path;

use anyhow::anyhow;
use scenarios::scenario::Scenario;
use vehicles::maneuver::{ManeuverConfig, ManeuverKind, run_maneuver};

use crate::output::{check_distinct, check_output_path};
use crate::report::{
    comparison_json, comparison_markdown, comparison_table, grid_table, study_table,
};
use crate::run_caption::RunCaption;

use crate::cli::args::{CompareArgs, GridArgs, ManeuverArgs, ManeuverName, ScenarioCommand};
use crate::cli::simulation::{Simulation, load_source, simulate};
use crate::cli::{Failure, Session, input, interrupted, out, outln, run_failure, write_output};

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

pub(crate) fn cmd_compare(args: &CompareArgs, session: &Session) -> Result<(), Failure> {
    for (i, name) in args.planners.iter().enumerate() {
        if args.planners[..i].contains(name) {
            return Err(input(anyhow!(
                "--planners: {name} is listed twice (each planner runs once)"
            )));
        }
    }
    let scenario = load_source(&args.source, &session.registry)?;
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
        crate::plots::check_plot_dir(dir, &vehicles).map_err(|e| input(anyhow!(e)))?;
    }
    let show_progress = !args.quiet && std::io::stderr().is_terminal();
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
        let finished = simulate(&scenario, &what, session)?;
        summaries.push(finished.summary.with_drawn(&scenario));
        time_series.push(finished.outcome.time_series);
        collisions.push(finished.outcome.safety.collisions);
    }
    if !args.quiet {
        out!("{}", comparison_table(&caption, &summaries));
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&comparison_json(&caption, &summaries))
            .map_err(run_failure)?;
        write_output(path, &text)?;
    }
    if let Some(path) = &args.markdown {
        write_output(path, &comparison_markdown(&caption, &summaries))?;
    }
    if let Some(dir) = &args.plots {
        let series: Vec<crate::plots::PlannerSeries<'_>> = summaries
            .iter()
            .zip(&time_series)
            .zip(&collisions)
            .map(|((s, rows), collisions)| crate::plots::PlannerSeries {
                planner: &s.planner,
                rows,
                collisions,
            })
            .collect();
        // The road as lanes, as the world builds it from the scenario's road.
        let lanes = scenario.instance(args.seed).sim.lanes().map_err(input)?;
        let written = crate::plots::write_comparison(
            dir,
            &lanes,
            args.lane_ids,
            &series,
            crate::plots::FigureSize::default(),
            &caption,
        )
        .map_err(run_failure)?;
        if !args.quiet {
            for path in written {
                outln!("wrote {}", path.display());
            }
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
        trace_period_s: args.trace_period_s,
        ..ManeuverConfig::default()
    };
    config.validate().map_err(input)?;
    let report = run_maneuver(&config).map_err(run_failure)?;
    let text = serde_json::to_string_pretty(&report).map_err(run_failure)?;
    if let Some(path) = &args.json {
        write_output(path, &text)?;
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
        ScenarioCommand::Expand { scenario, seed } => {
            let loaded = Scenario::load(scenario).map_err(input)?;
            let expanded = loaded.expanded(*seed);
            let text = expanded.to_toml().map_err(|e| input(anyhow!(e)))?;
            let what = match seed {
                Some(seed) => format!("the instance drawn with seed {seed}"),
                None => "the nominal instance".to_string(),
            };
            outln!(
                "# Generated by `merge_sim scenario expand`: {what} of {}, {} vehicles.",
                loaded.name,
                expanded.vehicles.len()
            );
            out!("{text}");
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

pub(crate) fn cmd_grid(args: &GridArgs, session: &Session) -> Result<(), Failure> {
    let interrupt = &session.interrupt;
    use crate::grid::{GridAxes, GridMetric, GridPlan, MAX_GRID_RUNS, job_count, run_grid};
    let scenario = load_source(&args.source, &session.registry)?;
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
        registry: std::sync::Arc::clone(&session.registry),
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
        crate::grid_plot::write_grid_png(
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
    out!("{}", crate::limits::markdown());
    Ok(())
}
