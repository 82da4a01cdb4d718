//! The command line: subcommands, their options and the parsers of option values.

use std::path::PathBuf;
use std::sync::Arc;

use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum};
use planner::ParameterSet;
use sim::registry::BehaviourRegistry;
use vehicles::maneuver::ManeuverConfig;

/// Cooperative merge simulator: potential-field planners with interactive speed optimisation
/// (Lin et al.) on physics-based Rapier vehicles.
///
/// With no subcommand, `merge_sim` runs the paper's urgent merge with PF-ISO, prints a summary
/// table and writes a Rerun recording (urgent_merge_pf-iso.rrd) in the current folder.
#[derive(Parser, Debug)]
#[command(name = "merge_sim", version, args_conflicts_with_subcommands = true)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Option<Command>,
    #[command(flatten)]
    pub(crate) run: RunArgs,
}

#[derive(Subcommand, Debug)]
pub(crate) enum Command {
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
    /// Combine the --json files of the shards of one sweep into the aggregate of the whole sweep
    /// (--json) and its rows in instance order (--jsonl, --parquet), after checking that every
    /// shard is there exactly once, complete and of the same sweep.
    MergeResults(MergeResultsArgs),
    /// Sensitivity grid: every planner on the same instances under {obstacles predicted in
    /// Eq. 7 on/off} × {sub-steps on/off} × path time gap τ × interaction time gap τ_I, with
    /// paired differences against the first planner.
    Grid(GridArgs),
    /// Run a study plan (TOML): factors × planners on the same instances, paired statistics
    /// against the reference planner (t-interval, t-test, Wilcoxon, Holm; collisions: McNemar,
    /// Newcombe), a report with tables, a figure and the plan's provenance. `merge_sim study
    /// --help` explains the plan format.
    Study(crate::cli::study_command::StudyArgs),
    /// Print the allowed range of every scenario value and the limits on runs, threads and
    /// work, as a Markdown table (the README's "Limits" section is this output).
    Limits,
    /// Read CommonRoad XML scenarios (formats 2020a and 2018b).
    #[command(subcommand)]
    Commonroad(CommonroadCommand),
    /// Read a road's geometry from an OpenDRIVE (.xodr) file.
    #[command(subcommand)]
    Opendrive(OpendriveCommand),
}

/// `merge_sim opendrive …`.
#[derive(Subcommand, Debug, Clone)]
pub(crate) enum OpendriveCommand {
    /// Print the road of lanes taken from an OpenDRIVE file as JSON on stdout: each mergesim
    /// lane's OpenDRIVE origin (`lanes`: id, road id, lane section, `<lane id>`, lane type) and
    /// the lanes themselves (`lane_road`: centrelines in travel direction, widths, links). Only
    /// drivable lanes are taken; elevation is dropped. Bad input: exit 2 naming the file.
    Dump {
        /// The OpenDRIVE file.
        file: std::path::PathBuf,
    },
}

/// `merge_sim commonroad …`.
#[derive(Subcommand, Debug, Clone)]
pub(crate) enum CommonroadCommand {
    /// Print what is read from a CommonRoad file as JSON on stdout: the lanelets, obstacles and
    /// planning problems as in the file (`scenario`), each obstacle's states in replay form
    /// (`replay`: interval midpoints, position rectangles' centres, time in s) and the road of
    /// lanes built from the lanelet network (`lane_road`). Bad input: exit 2 naming the file,
    /// the line and the element.
    Dump {
        /// The CommonRoad XML file.
        file: std::path::PathBuf,
    },
}

/// Which scenario, with which planner parameter set.
#[derive(Args, Debug, Clone)]
pub(crate) struct ScenarioArgs {
    /// Built-in scenario name, path to a scenario TOML file, or path to a CommonRoad XML file
    /// (`.xml`, formats 2020a and 2018b: its lanelet network, its obstacles as recorded
    /// traffic, the ego of its planning problem with its goal; docs/commonroad.md).
    #[arg(long, default_value = "urgent_merge", value_name = "NAME|PATH")]
    pub(crate) scenario: String,
    /// How a CommonRoad road's recorded vehicles move: `none` (left out), `replay` (along their
    /// recording, the default) or `reactive` (IDM once the recording would come too close to a
    /// simulated vehicle ahead) [default: the scenario's, replay for an .xml file]. Only for a
    /// scenario on a CommonRoad road.
    #[arg(long, value_name = "MODE", value_parser = parse_traffic_mode)]
    pub(crate) recorded_traffic: Option<sim::recorded_traffic::TrafficMode>,
    /// Simulated time (s), instead of the scenario's duration_s (for an .xml file: until its
    /// goal's time interval ends, else its last recorded state).
    #[arg(long, value_name = "SECONDS")]
    pub(crate) duration: Option<f64>,
    /// Planner parameter set: `paper` (the paper's literal reading) or `mergesim` (our
    /// improvements) [default: the scenario's `params`, else mergesim]. The scenario's
    /// [sim.planner] values apply on top of it.
    #[arg(long, value_name = "SET", value_parser = parse_params)]
    pub(crate) params: Option<ParameterSet>,
    /// What moves every car, instead of the scenario's `vehicle_model` choices: `rapier` (rigid
    /// body on four ray-cast wheels with Magic-Formula tyres, the default), `ks` (CommonRoad's
    /// kinematic single track), `st` (single track, linear tyres) or `std` (single-track drift
    /// model, Magic-Formula tyres); docs/vehicle_models.md.
    #[arg(long, value_name = "MODEL")]
    pub(crate) vehicle_model: Option<String>,
    /// Safety shield of every planner-driven vehicle, instead of the scenario's `[sim] shield`:
    /// `none` or `rss` (Responsibility-Sensitive Safety: in a dangerous situation the planned
    /// path is bounded by RSS's proper response; parameters `[sim.rss]`, docs/parameters.md).
    /// Human-driver models (`idm`, `idm-mobil`) are never shielded.
    #[arg(long, value_name = "SHIELD", value_parser = parse_shield)]
    pub(crate) shield: Option<sim::shield::ShieldKind>,
}

#[derive(Args, Debug, Clone)]
pub(crate) struct RunArgs {
    #[command(flatten)]
    pub(crate) source: ScenarioArgs,
    /// Planner of every planner-driven vehicle (overrides the scenario's choice).
    #[arg(long, value_name = "PLANNER")]
    pub(crate) planner: Option<String>,
    /// Run the scenario instance drawn with seed N from its [randomise] ranges (N also seeds
    /// the V2V drops); a sweep's per-run rows give each run's seed, written as 0x and 16 hex
    /// digits (decimal is read too; a float such as 9.853264649648847e18 is refused: it lost
    /// digits). Prints the seed and every value it drew on stderr (and under `drawn` in
    /// --json). Without it (or --sweep-seed) the nominal scenario runs.
    #[arg(long, value_name = "N", value_parser = parse_seed,
          conflicts_with_all = ["sweep_seed", "instance"])]
    pub(crate) seed: Option<u64>,
    /// With --instance I: run instance I of the sweep with seed K, exactly the run of that
    /// sweep's row I (seed SplitMix64::derive(K, I)); add the row's --planner for a
    /// multi-planner sweep.
    #[arg(long, value_name = "K", value_parser = parse_seed, requires = "instance")]
    pub(crate) sweep_seed: Option<u64>,
    /// The instance index of --sweep-seed (a sweep row's `instance`).
    #[arg(long, value_name = "I", requires = "sweep_seed")]
    pub(crate) instance: Option<u64>,
    /// Where to write the Rerun recording [default: <scenario>_<planner>.rrd, on a CommonRoad
    /// road <scenario>_<planner>[_<mode>][_<D>s].rrd (the --recorded-traffic mode unless
    /// `replay`, the --duration if given); none in a build without the cargo feature `rerun`].
    #[arg(long, value_name = "PATH", conflicts_with = "no_rrd")]
    pub(crate) rrd: Option<PathBuf>,
    /// Do not write a Rerun recording.
    #[arg(long)]
    pub(crate) no_rrd: bool,
    /// Open the recording in the Rerun viewer afterwards (needs `rerun` on PATH).
    #[arg(long, conflicts_with = "no_rrd")]
    pub(crate) view: bool,
    /// The vehicle the recording's follow view (and --gif) keeps in view [default: `ego`, or
    /// the scenario's first vehicle if none is called so]; an unknown name is refused before
    /// the run.
    #[arg(long, value_name = "NAME")]
    pub(crate) follow: Option<String>,
    /// Write a top-down animated GIF of the run here (drawn on the CPU: no GPU or display):
    /// the whole road or a window following --follow (--gif-view).
    #[arg(long, value_name = "PATH")]
    pub(crate) gif: Option<PathBuf>,
    /// Frames per second of the GIF, of simulated time and of playback (real time).
    #[arg(long, value_name = "FPS", default_value_t = 10.0, requires = "gif")]
    pub(crate) gif_fps: f64,
    /// Width of the GIF (pixels); the height follows from the road's width.
    #[arg(long, value_name = "PX", default_value_t = 800, requires = "gif")]
    pub(crate) gif_width: u32,
    /// What the GIF shows: `road`, the whole road with every vehicle in every frame (scaled to
    /// the width, across stretched so the lanes stay visible), or `follow`, a window of 30 m
    /// behind to 50 m ahead of --follow [default: road when more than two vehicles run, else
    /// follow].
    #[arg(long, value_name = "VIEW", value_enum, requires = "gif")]
    pub(crate) gif_view: Option<GifViewArg>,
    /// Write each lane's id on the road ("lane 1", at half the lane's length) in the
    /// recording (`world/road/lane_ids`) and the GIF.
    #[arg(long)]
    pub(crate) lane_ids: bool,
    /// Write the JSON summary here.
    #[arg(long, value_name = "PATH")]
    pub(crate) json: Option<PathBuf>,
    /// Write the time series (one row per vehicle per logged instant) here.
    #[arg(long, value_name = "PATH")]
    pub(crate) csv: Option<PathBuf>,
    /// Record potential fields and received shared paths for the first N vehicles only (by
    /// their order in the scenario), or for `all`; boxes, planned paths, time series and events
    /// are recorded for every vehicle.
    #[arg(long, value_name = "N|all", default_value = "4", value_parser = parse_record_detail)]
    pub(crate) record_detail: RecordDetail,
    /// Time each phase of the tick (V2V, planning, tracking, tire forces, physics, safety,
    /// metrics, recording) and print where the run's wall time went; also in --json.
    #[arg(long)]
    pub(crate) profile: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

impl RunArgs {
    /// The seed of the instance to run: --seed, or the seed of --instance of --sweep-seed
    /// (`None`: the nominal scenario).
    pub(crate) fn instance_seed(&self) -> Option<u64> {
        self.seed.or_else(|| {
            self.sweep_seed
                .zip(self.instance)
                .map(|(k, i)| crate::sweep::instance_seed(k, i))
        })
    }
}

/// `run --gif-view`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum GifViewArg {
    /// The whole road with every vehicle.
    Road,
    /// A window around the followed vehicle.
    Follow,
}

impl From<GifViewArg> for crate::animation::GifView {
    fn from(view: GifViewArg) -> Self {
        match view {
            GifViewArg::Road => Self::Road,
            GifViewArg::Follow => Self::Follow,
        }
    }
}

#[derive(Args, Debug)]
pub(crate) struct CompareArgs {
    #[command(flatten)]
    pub(crate) source: ScenarioArgs,
    /// Planners to compare, comma-separated, each once.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "pf-cs,pf-sp,pf-iso,pf-iso-pred"
    )]
    pub(crate) planners: Vec<String>,

    /// Compare on the scenario instance drawn with seed N (as `run --seed N`: decimal or 0x
    /// hex); without it the nominal scenario.
    #[arg(long, value_name = "N", value_parser = parse_seed)]
    pub(crate) seed: Option<u64>,
    /// Write the JSON here: the caption's scenario, params, seed and commit, then the runs'
    /// summaries under `runs`.
    #[arg(long, value_name = "PATH")]
    pub(crate) json: Option<PathBuf>,
    /// Write the table as Markdown here (its caption line first).
    #[arg(long, value_name = "PATH")]
    pub(crate) markdown: Option<PathBuf>,
    /// Write figures into this folder (created if missing; its parent must exist): paths.png
    /// (both vehicles' paths per planner, the paper's Fig. 3), states_<vehicle>.png
    /// (sideslip, yaw, yaw rate, speed over time per planner; states_obstacle.png is the
    /// paper's Fig. 4) and time_series.csv (their data).
    #[arg(long, value_name = "DIR")]
    pub(crate) plots: Option<PathBuf>,
    /// Write each lane's id on the road of paths.png ("lane 1", at half the lane's length).
    #[arg(long, requires = "plots")]
    pub(crate) lane_ids: bool,
    /// Print nothing but errors (no table, no progress, no "wrote" lines).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(Copy, Clone, Debug, ValueEnum)]
pub(crate) enum ManeuverName {
    /// Hold --speed-mps with the speed PID at fixed --steer-rad; report the settled state.
    SteadyState,
    /// Step the steering to --steer-rad at --speed-mps; report the response.
    StepSteer,
    /// Full braking from --speed-mps to standstill; report the stopping distance.
    Braking,
}

#[derive(Args, Debug)]
pub(crate) struct ManeuverArgs {
    /// Which test.
    pub(crate) maneuver: ManeuverName,
    /// Vehicle preset: bmw_320i, ford_escort, vw_vanagon.
    #[arg(long, default_value = "bmw_320i")]
    pub(crate) vehicle: String,
    /// Tire–road friction coefficient μ (> 0).
    #[arg(long, default_value_t = 0.8, allow_negative_numbers = true)]
    pub(crate) mu: f64,
    /// Speed (m/s).
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pub(crate) speed_mps: f64,
    /// Front wheel steering angle (rad).
    #[arg(long, default_value_t = 0.02, allow_negative_numbers = true)]
    pub(crate) steer_rad: f64,
    /// Physics step (s).
    #[arg(long, default_value_t = ManeuverConfig::default().dt_s, allow_negative_numbers = true)]
    pub(crate) dt_s: f64,
    /// Period of the report's `trace` (s), rounded to whole physics steps (at least one); 0
    /// records no trace.
    #[arg(long, default_value_t = ManeuverConfig::default().trace_period_s, allow_negative_numbers = true)]
    pub(crate) trace_period_s: f64,
    /// Write the report as JSON here.
    #[arg(long, value_name = "PATH")]
    pub(crate) json: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
pub(crate) enum ScenarioCommand {
    /// List the built-in scenarios.
    List,
    /// Print a built-in scenario as TOML (which `--scenario PATH` reads back unchanged).
    Show {
        /// Built-in name.
        name: String,
    },
    /// Print the platoon of `platoon_merge_50` with N vehicles as TOML (the scale scenarios of
    /// the scaling curve; N = 50 is the built-in).
    Platoon {
        /// Number of vehicles (1 to 200; the upper lane takes the odd one).
        #[arg(long, value_name = "N")]
        vehicles: usize,
    },
    /// Print the instance a scenario runs as TOML, every vehicle written out (those its
    /// [traffic] generates included): the nominal one, or with --seed N the one `run --seed N`
    /// draws.
    Expand {
        /// Built-in scenario name or path to a scenario TOML file.
        scenario: String,
        /// The instance drawn with seed N (decimal or 0x hex), as `run --seed N`.
        #[arg(long, value_name = "N", value_parser = parse_seed)]
        seed: Option<u64>,
    },
}

/// Parses the process's arguments with the planners of `registry`: `--planner` / `--planners`
/// accept exactly its names (an unknown one is clap's error, `invalid value 'X' for
/// '--planner <PLANNER>': unknown planner 'X'; valid: …`, exit 2) and their help lists them.
pub(crate) fn parse(registry: &Arc<BehaviourRegistry>) -> Cli {
    let matches = command_with(registry).get_matches();
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.format(&mut Cli::command()).exit())
}

/// The command line of [`Cli`] with its planner options bound to `registry`.
pub(crate) fn command_with(registry: &Arc<BehaviourRegistry>) -> clap::Command {
    let names = registry.names().join(", ");
    let bind = |arg: clap::Arg| {
        let help = arg.get_help().map(ToString::to_string).unwrap_or_default();
        arg.value_parser(planner_parser(Arc::clone(registry)))
            .help(format!("{help} [registered: {names}]"))
    };
    let models = registry.vehicle_models().names().join(", ");
    let bind_model = |arg: clap::Arg| {
        let help = arg.get_help().map(ToString::to_string).unwrap_or_default();
        arg.value_parser(vehicle_model_parser(Arc::clone(registry)))
            .help(format!("{help} [registered: {models}]"))
    };
    Cli::command()
        .mut_arg("planner", bind)
        .mut_arg("vehicle_model", bind_model)
        .mut_subcommand("run", |c| {
            c.mut_arg("planner", bind)
                .mut_arg("vehicle_model", bind_model)
        })
        .mut_subcommand("compare", |c| {
            c.mut_arg("planners", bind)
                .mut_arg("vehicle_model", bind_model)
        })
        .mut_subcommand("sweep", |c| {
            c.mut_arg("planner", bind)
                .mut_arg("planners", bind)
                .mut_arg("vehicle_model", bind_model)
        })
        .mut_subcommand("grid", |c| {
            c.mut_arg("planners", bind)
                .mut_arg("vehicle_model", bind_model)
        })
}

/// A vehicle model `registry` holds, else `unknown vehicle model 'X'; valid: …`.
fn vehicle_model_parser(
    registry: Arc<BehaviourRegistry>,
) -> impl Fn(&str) -> Result<String, String> + Clone + Send + Sync + 'static {
    move |text: &str| {
        let models = registry.vehicle_models();
        if models.contains(text) {
            Ok(text.to_string())
        } else {
            Err(models.unknown(text))
        }
    }
}

/// A name `registry` holds, else [`crate::experiment::unknown_planner`]'s message.
fn planner_parser(
    registry: Arc<BehaviourRegistry>,
) -> impl Fn(&str) -> Result<String, String> + Clone + Send + Sync + 'static {
    move |text: &str| {
        if registry.contains(text) {
            Ok(text.to_string())
        } else {
            Err(crate::experiment::unknown_planner(&registry, text))
        }
    }
}

pub(crate) fn parse_traffic_mode(text: &str) -> Result<sim::recorded_traffic::TrafficMode, String> {
    use sim::recorded_traffic::TrafficMode;
    match text {
        "none" => Ok(TrafficMode::None),
        "replay" => Ok(TrafficMode::Replay),
        "reactive" => Ok(TrafficMode::Reactive),
        other => Err(format!(
            "unknown mode {other:?} (valid: none, replay, reactive)"
        )),
    }
}

pub(crate) fn parse_shield(text: &str) -> Result<sim::shield::ShieldKind, String> {
    use sim::shield::ShieldKind;
    match text {
        "none" => Ok(ShieldKind::None),
        "rss" => Ok(ShieldKind::Rss),
        other => Err(format!("unknown shield {other:?} (valid: none, rss)")),
    }
}

pub(crate) fn parse_params(text: &str) -> Result<ParameterSet, String> {
    text.parse::<ParameterSet>().map_err(|e| e.to_string())
}

#[derive(Args, Debug)]
pub(crate) struct SweepArgs {
    #[command(flatten)]
    pub(crate) source: ScenarioArgs,
    /// Planner of every planner-driven vehicle (overrides the scenario's choice).
    #[arg(long, value_name = "PLANNER", conflicts_with = "planners")]
    pub(crate) planner: Option<String>,
    /// Paired sweep: run every instance with each of these planners (comma-separated; same
    /// seed, same drawn values) and report each planner's aggregate and the paired differences
    /// of each planner against the FIRST (the baseline): mean ± standard error of (planner −
    /// baseline) and the instances where it is better / worse / tied, for collisions, near
    /// misses, min gap, min TTC, peak yaw rate, peak sideslip, min speed and each vehicle's
    /// figures and the paper's. One name is the same as --planner.
    #[arg(long, value_name = "P1,P2,...", value_delimiter = ',')]
    pub(crate) planners: Vec<String>,
    /// Number of randomised instances in the whole sweep (1 to 1000000); each runs once per
    /// planner.
    #[arg(long, value_name = "N", value_parser = parse_runs)]
    pub(crate) runs: u64,
    /// Sweep seed K (decimal or 0x hex): instance i runs with seed SplitMix64::derive(K, i),
    /// which `run --sweep-seed K --instance i` (or `run --seed` with the row's seed) replays.
    /// The rows carry `sweep_seed` and `instance`.
    #[arg(long, value_name = "K", default_value = "0", value_parser = parse_seed)]
    pub(crate) seed: u64,
    /// Run only shard i of n (0-based): instances [⌊i·N/n⌋, ⌊(i+1)·N/n⌋). Default: from a Slurm
    /// job array (SLURM_ARRAY_TASK_ID, SLURM_ARRAY_TASK_COUNT), a Kubernetes Indexed Job
    /// (JOB_COMPLETION_INDEX with MERGESIM_SHARD_COUNT), else the whole sweep (0/1). On a
    /// cluster pass it explicitly (`--shard "$SLURM_ARRAY_TASK_ID/$SHARDS"`): a task resubmitted
    /// alone (`sbatch --array=2`) is an array of one task and would run the whole sweep. The
    /// sweep prints its shard on stderr, even with --quiet.
    #[arg(long, value_name = "i/n", value_parser = parse_shard)]
    pub(crate) shard: Option<crate::sweep::Shard>,
    /// Write the aggregate JSON here (with per-run samples, so shards can be merged).
    #[arg(long, value_name = "PATH")]
    pub(crate) json: Option<PathBuf>,
    /// Append one JSON line per run here as it finishes (the sweep's identity with its
    /// planners, instance, planner, seed, status, the drawn values under `drawn`, the figures,
    /// each vehicle's figures under `vehicles`, wall time), flushed at once, so an interrupted
    /// sweep loses no finished run. On a CommonRoad road a completed run's figures add
    /// `recorded_traffic` (the mode), `collisions_caused_by_replay`, `min_gap_to_recorded_m`,
    /// `min_ttc_to_recorded_s`, `goal_reached`, `goal_time_s` (also in --json and --parquet).
    /// An existing file is refused unless --resume is given.
    #[arg(long, value_name = "PATH")]
    pub(crate) jsonl: Option<PathBuf>,
    /// Complete an interrupted sweep: read the --jsonl file of the same sweep (same scenario,
    /// parameters, planner(s), --runs, --seed and shard), run only the (instance, planner) runs
    /// it lacks and append them; the aggregate then equals an uninterrupted sweep's.
    #[arg(long, requires = "jsonl")]
    pub(crate) resume: bool,
    /// Write every row (instance, planner, seed, status, error, run figures, `drawn.<name>`,
    /// `<vehicle>.<figure>`) as one Parquet file here (seed as uint64).
    #[arg(long, value_name = "PATH")]
    pub(crate) parquet: Option<PathBuf>,
    /// Worker threads [default: one per core].
    #[arg(long, value_name = "N", value_parser = parse_threads)]
    pub(crate) threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(Args, Debug)]
pub(crate) struct MergeResultsArgs {
    /// The `sweep --json` files of every shard of one sweep, in any order. Each shard i/n must
    /// be given exactly once, complete, and of the same sweep (scenario and its fingerprint,
    /// parameters, planners, --runs, --seed, shard count); otherwise nothing is written and
    /// the error names the file (exit 2).
    #[arg(required = true, value_name = "SHARD_JSON")]
    pub(crate) inputs: Vec<PathBuf>,
    /// Write the aggregate of the whole sweep here: what the unsharded sweep's --json holds,
    /// except `wall_time_s`, here the sum of the shards' wall times (the time the shards
    /// took together, not the elapsed time of the array).
    #[arg(long, value_name = "PATH")]
    pub(crate) json: Option<PathBuf>,
    /// Write the rows of the whole sweep as JSONL here, in instance order (then in the sweep's
    /// planner order): the unsharded sweep's --jsonl rows, sorted, each with the whole sweep's
    /// identity; `wall_time_s` is null (a shard's --json keeps no per-run wall times). Taken
    /// from the validated shard files, so unlike `cat shard_*.jsonl` it is checked and ordered.
    /// An existing regular file is replaced, as with --json and --parquet.
    #[arg(long, value_name = "PATH")]
    pub(crate) jsonl: Option<PathBuf>,
    /// Write the rows of the whole sweep as one Parquet file here (as `sweep --parquet`).
    #[arg(long, value_name = "PATH")]
    pub(crate) parquet: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(Args, Debug)]
pub(crate) struct GridArgs {
    #[command(flatten)]
    pub(crate) source: ScenarioArgs,
    /// Planners, comma-separated; the first is the reference of the paired differences.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "pf-cs,pf-sp,pf-iso,pf-iso-pred"
    )]
    pub(crate) planners: Vec<String>,
    /// Path-field time gaps τ (s), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "0,1,2,3", value_parser = parse_gap)]
    pub(crate) path_gaps: Vec<f64>,
    /// Interaction time gaps τ_I (s), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2,3", value_parser = parse_gap)]
    pub(crate) interaction_gaps: Vec<f64>,
    /// Run only the parameter set's own cell (its prediction, sub-steps, τ and τ_I): a paired
    /// study of the planners as configured, with a table of paired differences for every
    /// vehicle and figure.
    #[arg(long, conflicts_with_all = ["path_gaps", "interaction_gaps"])]
    pub(crate) base_only: bool,
    /// Instances per cell: 0 runs the nominal scenario only; N runs the instances a sweep
    /// with --seed would (instance i with seed SplitMix64::derive(seed, i)).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub(crate) runs: u64,
    /// Sweep seed of the drawn instances (decimal or 0x hex).
    #[arg(long, default_value = "0", value_name = "K", value_parser = parse_seed)]
    pub(crate) seed: u64,
    /// Vehicle whose figures the table and the figure compare [default: the scenario's
    /// vehicle named `obstacle` (the built-in merges' car in the through lane, beside which
    /// the ego merges), else its first vehicle not named `ego`, else its first vehicle (the
    /// ego of a CommonRoad file)].
    #[arg(long, value_name = "NAME")]
    pub(crate) vehicle: Option<String>,
    /// Write every run (one line per run and vehicle) here.
    #[arg(long, value_name = "PATH")]
    pub(crate) csv: Option<PathBuf>,
    /// Write the runs and the paired differences as JSON here.
    #[arg(long, value_name = "PATH")]
    pub(crate) json: Option<PathBuf>,
    /// Write the figure (heat maps of the mean ratio of the vehicle's peak yaw rate to the
    /// first planner's) here.
    #[arg(long, value_name = "PATH")]
    pub(crate) plot: Option<PathBuf>,
    /// Worker threads [default: one per core].
    #[arg(long, value_name = "N", value_parser = parse_threads)]
    pub(crate) threads: Option<usize>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// A seed: decimal digits or 0x and hex digits (what the result files write); a float is
/// refused, as it cannot be an exact seed.
pub(crate) fn parse_seed(text: &str) -> Result<u64, String> {
    crate::exact_seed::parse_seed(text).map_err(|e| e.to_string())
}

pub(crate) fn parse_runs(text: &str) -> Result<u64, String> {
    use crate::sweep::MAX_RUNS;
    match text.parse::<u64>() {
        Ok(n) if (1..=MAX_RUNS).contains(&n) => Ok(n),
        _ => Err(format!(
            "expected a whole number of runs from 1 to {MAX_RUNS} (for more, run several sweeps \
             with different seeds)"
        )),
    }
}

pub(crate) fn parse_threads(text: &str) -> Result<usize, String> {
    use crate::sweep::MAX_THREADS;
    match text.parse::<usize>() {
        Ok(n) if (1..=MAX_THREADS).contains(&n) => Ok(n),
        _ => Err(format!(
            "expected a whole number of threads from 1 to {MAX_THREADS}"
        )),
    }
}

pub(crate) fn parse_shard(text: &str) -> Result<crate::sweep::Shard, String> {
    text.parse()
        .map_err(|e: crate::sweep::ShardError| e.to_string())
}

pub(crate) fn parse_gap(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() && (0.0..=10.0).contains(&v) => Ok(v),
        _ => Err("expected a time gap in [0, 10] s".into()),
    }
}

/// How many vehicles get fields and received paths in the recording.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct RecordDetail(pub(crate) Option<usize>);

pub(crate) fn parse_record_detail(text: &str) -> Result<RecordDetail, String> {
    if text == "all" {
        return Ok(RecordDetail(None));
    }
    text.parse::<usize>()
        .map(|n| RecordDetail(Some(n)))
        .map_err(|_| "expected a number of vehicles or `all`".into())
}
