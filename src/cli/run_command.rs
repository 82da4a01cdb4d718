//! `merge_sim run`: one pipeline, each step once.
//!
//! 1. [`load`]: the scenario, the planner's label, the seed and every output path, resolved
//!    from the arguments once into a [`RunJob`] (no later step reads the arguments);
//! 2. [`RunJob::check`]: every output path, the followed vehicle, the GIF's parameters, the
//!    recording's size — before any work;
//! 3. [`RunJob::simulate`]: the run with its observers (the recording; the time series kept
//!    for the CSV rows and the GIF frames);
//! 4. [`RunJob::write`]: the GIF, the JSON, the CSV, the printed summary, the viewer.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{Context, anyhow};
use scenarios::scenario::Scenario;

use crate::animation::{GifParams, GifView};
use crate::cli::args::RunArgs;
use crate::cli::commands::{check_outputs, scenario_file};
use crate::cli::simulation::{Simulation, load_source, simulate};
use crate::cli::{Failure, Session, input, out, outln, run_failure, write_output};
use crate::experiment::{Finished, planner_label};
use crate::report::time_series_csv;

/// Recordings estimated above this size are announced before they are written.
const RECORDING_WARNING_BYTES: f64 = 500e6;

/// `merge_sim run` (and `merge_sim` with no subcommand).
pub(crate) fn cmd_run(args: &RunArgs, session: &Session) -> Result<(), Failure> {
    let job = load(args, &session.registry)?;
    let follow = job.check()?;
    let finished = job.simulate(&follow, session)?;
    job.write(&follow, &finished)
}

/// What one `run` does, resolved from its arguments.
struct RunJob<'a> {
    scenario: Scenario,
    /// The scenario file read (none for a built-in): no output may be it.
    inputs: Vec<&'a Path>,
    /// `--planner` (None: the scenario's own).
    planner: Option<&'a str>,
    /// The instance's seed (None: the nominal scenario) and, for `--sweep-seed K --instance I`,
    /// (K, I).
    seed: Option<u64>,
    sweep_instance: Option<(u64, u64)>,
    /// The recording (None: none).
    rrd: Option<PathBuf>,
    json: Option<&'a Path>,
    csv: Option<&'a Path>,
    /// `--gif` and how it is drawn.
    gif: Option<(&'a Path, GifParams)>,
    /// `--follow` as asked.
    follow: Option<&'a str>,
    record_detail: Option<usize>,
    profile: bool,
    lane_ids: bool,
    view: bool,
    quiet: bool,
    show_progress: bool,
}

/// The Rerun viewer's command (`--view`).
const VIEWER: &str = "rerun";

/// Whether an executable file `name` is in one of PATH's folders.
fn on_path(name: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|dir| is_executable(&dir.join(name)))
    })
}

#[cfg(unix)]
fn is_executable(path: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt as _;
    std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

#[cfg(not(unix))]
fn is_executable(path: &Path) -> bool {
    path.is_file() || path.with_extension("exe").is_file()
}

/// Step 1: loads the scenario and resolves every argument.
fn load<'a>(
    args: &'a RunArgs,
    registry: &sim::registry::BehaviourRegistry,
) -> Result<RunJob<'a>, Failure> {
    let scenario = load_source(&args.source, registry)?;
    if !cfg!(feature = "rerun") && (args.rrd.is_some() || args.view) {
        return Err(input(anyhow!(
            "{}",
            sim::recording::RecordingError::Unsupported
        )));
    }
    // Without Rerun support a run records nothing unless asked to (and then refuses, above).
    let rrd = if args.no_rrd || !cfg!(feature = "rerun") {
        None
    } else {
        Some(args.rrd.clone().unwrap_or_else(|| {
            let label = planner_label(&scenario, args.planner.as_deref());
            default_rrd(&scenario, &label, args.source.duration)
        }))
    };
    let gif = args.gif.as_deref().map(|path| {
        let params = GifParams {
            fps: args.gif_fps,
            width_px: args.gif_width,
            view: args
                .gif_view
                .map_or_else(|| GifView::default_for(scenario.vehicles.len()), Into::into),
            lane_ids: args.lane_ids,
            ..GifParams::default()
        };
        (path, params)
    });
    Ok(RunJob {
        inputs: scenario_file(&args.source.scenario),
        scenario,
        planner: args.planner.as_deref(),
        seed: args.instance_seed(),
        sweep_instance: args.sweep_seed.zip(args.instance),
        rrd,
        json: args.json.as_deref(),
        csv: args.csv.as_deref(),
        gif,
        follow: args.follow.as_deref(),
        record_detail: args.record_detail.0,
        profile: args.profile,
        lane_ids: args.lane_ids,
        view: args.view,
        quiet: args.quiet,
        show_progress: !args.quiet && std::io::stderr().is_terminal(),
    })
}

impl RunJob<'_> {
    /// Step 2: every check before any work; returns the vehicle the recording and the GIF
    /// follow.
    fn check(&self) -> Result<String, Failure> {
        check_outputs(
            &[
                (self.rrd.as_deref(), "--rrd"),
                (self.json, "--json"),
                (self.csv, "--csv"),
                (self.gif.as_ref().map(|(path, _)| *path), "--gif"),
            ],
            &self.inputs,
        )?;
        let follow = followed_vehicle(&self.scenario, self.follow)?;
        if self.view && self.rrd.is_some() && !on_path(VIEWER) {
            return Err(input(anyhow!(
                "--view: the Rerun viewer `{VIEWER}` is not on PATH (install: pip install \
                 rerun-sdk==0.36.3), or leave --view out and open the recording later"
            )));
        }
        if let Some((_, params)) = &self.gif {
            params.validate().map_err(input)?;
        }
        if let Some(path) = &self.rrd {
            let instance = self.scenario.instance(self.seed);
            let bytes = sim::recording::size_estimate::estimated_bytes(
                &instance.sim,
                &instance.vehicles,
                self.record_detail,
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
        Ok(follow)
    }

    /// Step 3: the run, with its observers: the recording, and the time series kept for the
    /// CSV rows and the GIF frames.
    fn simulate(&self, follow: &str, session: &Session) -> Result<Finished, Failure> {
        if let Some(seed) = self.seed
            && !self.quiet
        {
            // stderr: stdout stays the table it always was.
            eprint!(
                "{}",
                crate::sweep::describe_instance(&self.scenario, seed, self.sweep_instance)
            );
        }
        let what = Simulation {
            planner: self.planner,
            seed: self.seed,
            rrd: self.rrd.as_deref(),
            keep_time_series: self.csv.is_some() || self.gif.is_some(),
            show_progress: self.show_progress,
            profile: self.profile,
            record_detail: self.record_detail,
            follow: Some(follow),
            lane_ids: self.lane_ids,
        };
        let mut finished = simulate(&self.scenario, &what, session)?;
        finished.summary = finished.summary.with_drawn(&self.scenario);
        Ok(finished)
    }

    /// Step 4: every output, then the printed summary and the viewer.
    fn write(&self, follow: &str, finished: &Finished) -> Result<(), Failure> {
        if let Some((path, params)) = &self.gif {
            self.write_gif(path, params, follow, finished)?;
        }
        if let Some(path) = self.json {
            let text = serde_json::to_string_pretty(&finished.summary).map_err(run_failure)?;
            write_output(path, &text)?;
        }
        if let Some(path) = self.csv {
            write_output(path, &time_series_csv(&finished.outcome.time_series))?;
        }
        if !self.quiet {
            out!("{}", finished.summary.table());
            for event in &finished.summary.events {
                outln!("event: {event}");
            }
            if let Some(profile) = &finished.summary.profile {
                out!("\nwhere the wall time went:\n{}", profile.table());
            }
            if let Some(path) = &self.rrd {
                outln!(
                    "recording: {} (open with `rerun {}`)",
                    path.display(),
                    path.display()
                );
            }
        }
        if self.view
            && let Some(path) = &self.rrd
        {
            std::process::Command::new(VIEWER)
                .arg(path)
                .spawn()
                .context(
                    "cannot start the Rerun viewer `rerun` (install: pip install rerun-sdk==0.36.3)",
                )
                .map_err(run_failure)?;
        }
        Ok(())
    }

    /// Writes `--gif` from the run's time series and prints where it went.
    fn write_gif(
        &self,
        path: &Path,
        params: &GifParams,
        follow: &str,
        finished: &Finished,
    ) -> Result<(), Failure> {
        use crate::animation::{GifVehicle, write_gif};
        let instance = self.scenario.instance(self.seed);
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
        let show_progress = self.show_progress;
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
        if !self.quiet {
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
}

/// The default recording of a run: `<scenario>_<planner>.rrd`; on a CommonRoad road, with
/// `_<mode>` when its recorded traffic is not replayed (the default) and `_<duration>s` when
/// `--duration` is given, so that runs of one file in different modes do not overwrite each
/// other.
fn default_rrd(scenario: &Scenario, label: &str, duration_s: Option<f64>) -> PathBuf {
    use crate::output::file_name_part;
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
