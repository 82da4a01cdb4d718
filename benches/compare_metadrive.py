#!/usr/bin/env python3
"""Paired, interleaved throughput comparison: mergesim (>= 10 Rapier vehicles) vs MetaDrive.

Run through benches/compare_metadrive.sh, which sets up the venv (pinned MetaDrive), the asset
placeholders MetaDrive needs offline, and the binary. The figure compared is simulated
vehicle-seconds per wall-clock second. What each side simulates -- they are not the same model,
and this is a throughput comparison, not a like-for-like one:

  * MetaDrive (`metadrive-simulator`, physics-only: use_render=False, image_observation=False,
    so no Panda3D window, camera or image sensor): `MetaDriveEnv` with its defaults -- a
    procedurally generated map of 3 blocks, 3 lanes of 3.5 m, traffic_density 0.1 in "trigger"
    mode (each block's traffic is spawned at reset, parked, and starts driving with MetaDrive's
    IDMPolicy when the ego reaches that block; a traffic vehicle leaving its lane is removed),
    Bullet ray-cast vehicles (panda3d's Bullet) stepped at physics_world_step_size 0.02 s,
    decision_repeat 5 (one env.step() = 5 Bullet steps = 0.1 s), the default
    LidarStateObservation (ego state, navigation and a 240-beam, 50 m lidar cast in Bullet every
    env.step()), reward and termination checks. The one change from the defaults: the ego is
    driven by MetaDrive's own IDMPolicy (`agent_policy=IDMPolicy`, the traffic's driver, which
    follows the route and changes lanes) instead of actions fed to env.step(), so it drives the
    route to its destination (with a constant action it leaves the road within ~6 s and resets
    would dominate). One repetition = --md-episodes episodes, `reset(seed=s)` for
    s = --md-seed ... (num_scenarios = --md-episodes, so the maps are MetaDrive's scenarios
    start_seed..start_seed+n-1, the same in every repetition), each run until termination
    (arrival, crash, out of road) or a safety cap of --md-max-steps env.steps.
    Vehicle-seconds = sum over env.steps of (vehicles in that step) x decision_repeat x
    physics_world_step_size, where "vehicles" is counted two ways from the same timed samples:
      - driving: the ego + the traffic vehicles driving during that step (those active before
        the step, those triggered in it and those removed after it: the union of the traffic
        manager's active list before and after the step) -- the main row;
      - in the Bullet world: the above + the parked, not yet triggered traffic, which is also
        in the Bullet world and stepped by it -- a second row, favourable to MetaDrive.
    Timed: env.reset() and env.step() calls only (env construction, imports and the counting
    done here between steps excluded); the steps-only time is the second column.
    MetaDrive, N processes at once (--md-procs, default every core): the same, in N worker
    processes of this script, each with its own env and the same episodes, told to start
    together every repetition; the repetition's time is the slowest worker's own reset + step
    time, its vehicle-seconds the workers' sum. It is the all-cores figure to set beside
    mergesim's `sweep` (one MetaDrive process uses one core).
  * mergesim: the platoon of `platoon_merge_50` with --vehicles N cars (`merge_sim scenario
    platoon --vehicles N`, the scale scenarios of the README's scaling table; N = 10: 5 per lane
    at 20 m/s zipping into one lane, 72 s): Rapier rigid-body vehicles stepped at 500 Hz (or at
    --dt-s: the physics steps at which the vehicle is valid, benches/physics_step_validity.py) with
    tire forces, each re-planning at 10 Hz with PF-ISO (potential field + Clarabel QPs) against
    the others in range, V2V, tracking, safety metrics and the JSON summary. Vehicle-seconds =
    vehicles x duration_s. Three variants:
      - `run`, one core: `merge_sim run --scenario P --no-rrd --json OUT --quiet` with
        RAYON_NUM_THREADS=1 (the vehicles of a tick plan one after the other);
      - `run`, all cores: the same with rayon's default (the vehicles of a tick plan in
        parallel on every core);
      - `sweep`, all cores: `merge_sim sweep --scenario P --runs K --threads T --seed 42 --json
        OUT --quiet`, K randomised instances of the platoon (its [randomise] ranges) on T worker
        threads (default: every core); vehicle-seconds summed over the completed runs.
    With --also-planner NAME, the `run` on one core and the `sweep` also run with `--planner NAME`
    (every vehicle), e.g. idm-mobil: IDM + MOBIL, the kind of driver MetaDrive's IDMPolicy is, so
    the simulator's cost can be read apart from PF-ISO's planning.
    Timed: the whole merge_sim process, measured here around the subprocess (process start-up,
    scenario parsing and JSON writing included: conservative for mergesim); the JSON's
    in-process `wall_time_s` is the second column.

One untimed warm-up of each variant comes first (for MetaDrive: every scenario's reset, so all
maps are generated and cached as in the timed repetitions, and one whole episode); then the
variants are run interleaved, round by round (MetaDrive, mergesim run 1 core, mergesim run all
cores, mergesim sweep, MetaDrive, ...). Markdown goes to stdout (MetaDrive's own output is sent
to stderr); --json writes all raw samples.
"""
from __future__ import annotations

import argparse
import importlib.metadata as md
import json
import logging
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

from bench_common import loadavg, log, provenance, with_physics_step


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bin", required=True, help="path of the merge_sim binary")
    p.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."),
                   help="mergesim checkout (for the git commit)")
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--vehicles", type=int, default=10, help="mergesim platoon size (>= 10 asked for)")
    p.add_argument("--sweep-runs", type=int, default=4, help="instances per mergesim sweep repetition")
    p.add_argument("--threads", type=int, default=os.cpu_count() or 1,
                   help="worker threads of the mergesim sweep (default: every core)")
    p.add_argument("--md-episodes", type=int, default=10)
    p.add_argument("--md-seed", type=int, default=0)
    p.add_argument("--md-traffic-density", type=float, default=None,
                   help="MetaDrive traffic_density (default: MetaDrive's own, 0.1)")
    p.add_argument("--md-max-steps", type=int, default=3000, help="safety cap of env.steps per episode")
    p.add_argument("--md-procs", type=int, default=os.cpu_count() or 1,
                   help="MetaDrive processes run at once for the all-cores row (default: every core; "
                        "1 leaves the row out)")
    p.add_argument("--md-worker", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--dt-s", type=float, default=None,
                   help="physics step of the mergesim platoon, [sim] dt_s (default: the scenario's, 0.002 s)")
    p.add_argument("--also-speed-program", default=None,
                   help="also run the mergesim sweep with this [sim.planner] speed_program "
                        "(e.g. newton-qp-banded), interleaved with the others")
    p.add_argument("--also-planner", default=None,
                   help="also run the mergesim `run` on one core and the `sweep` with this planner in "
                        "place of PF-ISO (`--planner NAME`, e.g. idm-mobil: MetaDrive's kind of driver), "
                        "interleaved with the others")
    p.add_argument("--json", dest="json_path", default=None)
    a = p.parse_args()
    if a.also_planner is not None and not a.also_planner.strip():
        p.error("--also-planner needs a planner name")
    if min(a.reps, a.vehicles, a.sweep_runs, a.threads, a.md_episodes, a.md_max_steps, a.md_procs) < 1:
        p.error("--reps, --vehicles, --sweep-runs, --threads, --md-episodes, --md-max-steps, --md-procs "
                "must be >= 1")
    return a


def version(name: str) -> str:
    try:
        return md.version(name)
    except md.PackageNotFoundError:
        return "not installed"


def environment(args: argparse.Namespace) -> dict:
    env = provenance(args.root, args.bin, {
        "metadrive_simulator": version("metadrive-simulator"),
        "panda3d": version("panda3d"),
        "gymnasium": version("gymnasium"),
        "numpy": version("numpy"),
    })
    env["merge_sim"] = os.path.abspath(args.bin)
    return env


class MetaDrive:
    """MetaDriveEnv, physics only, default traffic, IDM-driven ego, episodes to termination."""

    def __init__(self, args: argparse.Namespace) -> None:
        from metadrive.envs.metadrive_env import MetaDriveEnv
        from metadrive.policy.idm_policy import IDMPolicy

        self.user_config = dict(
            use_render=False,
            image_observation=False,
            num_scenarios=args.md_episodes,
            start_seed=args.md_seed,
            agent_policy=IDMPolicy,
            log_level=logging.WARNING,
        )
        if args.md_traffic_density is not None:
            self.user_config["traffic_density"] = args.md_traffic_density
        self.env = MetaDriveEnv(dict(self.user_config))
        self.cfg = self.env.config
        self.dt = float(self.cfg["physics_world_step_size"])
        self.repeat = int(self.cfg["decision_repeat"])
        self.episodes = args.md_episodes
        self.seed0 = args.md_seed
        self.max_steps = args.md_max_steps
        self.label = "MetaDrive (driving vehicles)"
        self.label_all = "MetaDrive (+ parked traffic in the Bullet world)"

    def config(self) -> dict:
        c = {k: (v.__name__ if isinstance(v, type) else v) for k, v in self.user_config.items()}
        keep = ("map", "traffic_density", "traffic_mode", "need_inverse_traffic", "random_traffic",
                "physics_world_step_size", "decision_repeat", "horizon", "accident_prob",
                "use_mesh_terrain", "show_terrain")
        effective = {k: self.cfg[k] for k in keep if k in self.cfg}
        obs = self.env.observation_space
        effective["observation"] = f"{type(self.env.observations[next(iter(self.env.observations))]).__name__}" \
            if getattr(self.env, "observations", None) else "unknown"
        effective["observation_shape"] = list(getattr(obs, "shape", []) or [])
        effective["lidar"] = dict(self.cfg["vehicle_config"]["lidar"])
        effective["map_config"] = {str(k): v for k, v in dict(self.cfg["map_config"]).items()}
        return {
            "user_config": c,
            "effective": effective,
            "ego": "IDMPolicy (agent_policy); the action passed to env.step() is ignored",
            "episodes_per_rep": self.episodes,
            "seeds": [self.seed0, self.seed0 + self.episodes - 1],
            "episode_end": f"termination/truncation; safety cap {self.max_steps} env.steps",
        }

    def warm_up(self) -> None:
        for k in range(self.episodes):
            self.env.reset(seed=self.seed0 + k)
        self.run(episodes=1)

    def run(self, episodes: int | None = None) -> dict:
        episodes = self.episodes if episodes is None else episodes
        env = self.env
        step_s = self.repeat * self.dt
        pc = time.perf_counter
        cpu0 = time.process_time()
        t_reset = t_step = 0.0
        veh_s = veh_s_all = sim_s = 0.0
        ep_len_s, ends = [], []
        max_driving = max_all = 0
        capped = 0
        action = [0.0, 0.0]
        for k in range(episodes):
            t0 = pc()
            env.reset(seed=self.seed0 + k)
            t_reset += pc() - t0
            tm = env.engine.traffic_manager
            steps = 0
            while True:
                ego = len(env.agents)
                before = {v.id for v in tm._traffic_vehicles}
                t0 = pc()
                _, _, terminated, truncated, info = env.step(action)
                t_step += pc() - t0
                driving = ego + len(before | {v.id for v in tm._traffic_vehicles})
                parked = sum(len(b.vehicles) for b in tm.block_triggered_vehicles)
                veh_s += driving * step_s
                veh_s_all += (driving + parked) * step_s
                max_driving = max(max_driving, driving)
                max_all = max(max_all, driving + parked)
                sim_s += step_s
                steps += 1
                if terminated or truncated:
                    break
                if steps >= self.max_steps:
                    capped += 1
                    break
            ep_len_s.append(steps * step_s)
            end = [key for key in ("arrive_dest", "crash_vehicle", "crash_object", "out_of_road", "max_step")
                   if info.get(key)]
            ends.append(",".join(end) or "other")
        cpu = time.process_time() - cpu0
        return {
            "wall_s": t_reset + t_step,
            "cpu_s": cpu,  # process CPU time over the whole loop (counting included)
            "inner_wall_s": t_step,
            "reset_s": t_reset,
            "vehicle_s": veh_s,
            "vehicle_s_all": veh_s_all,
            "sim_s": sim_s,
            "max_vehicles": max_driving,
            "max_vehicles_all": max_all,
            "episode_len_s": ep_len_s,
            "episode_ends": ends,
            "capped": capped,
        }

    def close(self) -> None:
        self.env.close()


def worker_main(args: argparse.Namespace) -> int:
    """One MetaDrive process of the all-cores row: builds and warms up its env, says `ready`, then
    runs one repetition per `go` line on stdin and answers with its sample as one JSON line."""
    proto = os.fdopen(os.dup(1), "w", encoding="utf-8")
    sys.stdout.flush()
    os.dup2(2, 1)  # MetaDrive's own printing goes to stderr, the protocol to the real stdout
    mdv = MetaDrive(args)
    try:
        mdv.warm_up()
        print("ready", file=proto, flush=True)
        for line in sys.stdin:
            if line.strip() != "go":
                break
            print(json.dumps(mdv.run()), file=proto, flush=True)
    finally:
        mdv.close()
    return 0


class MetaDrivePool:
    """--md-procs MetaDrive processes, each with its own env and the same episodes, started at
    once every repetition: MetaDrive on every core (one process uses one). A repetition's wall
    time is the slowest worker's own reset() + step() time (favourable to MetaDrive: start-up,
    the pipe and the counting are excluded); its vehicle-seconds are the workers' sum."""

    def __init__(self, args: argparse.Namespace) -> None:
        cmd = [sys.executable, os.path.abspath(__file__), "--md-worker", "--bin", args.bin,
               "--md-episodes", str(args.md_episodes), "--md-seed", str(args.md_seed),
               "--md-max-steps", str(args.md_max_steps)]
        if args.md_traffic_density is not None:
            cmd += ["--md-traffic-density", str(args.md_traffic_density)]
        self.cmd = cmd
        self.procs = [subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
                      for _ in range(args.md_procs)]
        self.label = f"MetaDrive, {args.md_procs} processes at once (driving vehicles)"

    def warm_up(self) -> None:
        for p in self.procs:
            line = p.stdout.readline().strip()
            if line != "ready":
                raise SystemExit(f"MetaDrive worker failed to start: {line!r}")

    def run(self) -> dict:
        for p in self.procs:
            p.stdin.write("go\n")
            p.stdin.flush()
        got = []
        for p in self.procs:
            line = p.stdout.readline()
            if not line:
                raise SystemExit("a MetaDrive worker died")
            got.append(json.loads(line))
        return {
            "wall_s": max(g["wall_s"] for g in got),
            "inner_wall_s": max(g["inner_wall_s"] for g in got),
            "cpu_s": sum(g["cpu_s"] for g in got),
            "vehicle_s": sum(g["vehicle_s"] for g in got),
            "vehicle_s_all": sum(g["vehicle_s_all"] for g in got),
            "sim_s": sum(g["sim_s"] for g in got),
            "workers": got,
        }

    def close(self) -> None:
        for p in self.procs:
            try:
                p.stdin.close()
            except OSError:
                pass
            p.wait(timeout=60)


class MergeSim:
    """One `merge_sim run` or `merge_sim sweep` process per repetition."""

    def __init__(self, bin_path: str, scenario: str, out: str, kind: str, args: argparse.Namespace,
                 key: str | None = None, note: str = "", extra: tuple[str, ...] = ()) -> None:
        self.kind = kind
        self.key = key or kind
        self.out = out
        self.env = dict(os.environ)
        if kind == "run1":
            self.cmd = [bin_path, "run", "--scenario", scenario, "--no-rrd", "--json", out, "--quiet"]
            self.env["RAYON_NUM_THREADS"] = "1"
            self.label = "mergesim `run`, one core (RAYON_NUM_THREADS=1)"
        elif kind == "run":
            self.cmd = [bin_path, "run", "--scenario", scenario, "--no-rrd", "--json", out, "--quiet"]
            self.env.pop("RAYON_NUM_THREADS", None)
            self.label = "mergesim `run`, all cores"
        else:
            self.cmd = [bin_path, "sweep", "--scenario", scenario, "--runs", str(args.sweep_runs),
                        "--threads", str(args.threads), "--seed", "42", "--json", out, "--quiet"]
            self.env.pop("RAYON_NUM_THREADS", None)
            self.label = f"mergesim `sweep` of {args.sweep_runs}, {args.threads} threads{note}"
        if kind == "run1" and note:
            self.label += note
        self.cmd += list(extra)
        # The planner every vehicle runs when the command overrides the scenario's (--planner).
        self.planner_override = extra[extra.index("--planner") + 1] if "--planner" in extra else None
        self.duration_s: float | None = None  # set from a `run` JSON (sweep JSON has no duration)

    def run(self) -> dict:
        if os.path.exists(self.out):
            os.remove(self.out)
        ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(self.cmd, env=self.env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        wall = time.perf_counter() - t0
        ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)
        if proc.returncode != 0:
            raise SystemExit(f"merge_sim failed ({proc.returncode}): {' '.join(self.cmd)}\n{proc.stderr}")
        with open(self.out, encoding="utf-8") as f:
            d = json.load(f)
        if self.kind == "sweep":
            done = [s for s in d["samples"] if s.get("status") == "completed"]
            if len(done) != len(d["samples"]):
                raise SystemExit(f"merge_sim sweep: {len(d['samples']) - len(done)} runs did not complete")
            if self.duration_s is None:
                raise SystemExit("internal: sweep duration unknown")
            if any(k.endswith("duration_s") for s in done for k in (s.get("drawn") or {})):
                raise SystemExit("the sweep draws the duration: vehicles x duration_s would be wrong")
            n_veh = [len(s["vehicles"]) for s in done]
            vehicle_s = sum(n_veh) * self.duration_s
            # Check: every vehicle planned every planner period of the whole run.
            plans = sum(int(s.get("plans", 0)) for s in done)
            return {
                "wall_s": wall, "cpu_s": cpu, "inner_wall_s": float(d["wall_time_s"]),
                "vehicle_s": vehicle_s, "sim_s": self.duration_s * len(done),
                "vehicles": sorted(set(n_veh)), "runs": len(done), "plans": plans,
                "collisions": d.get("collisions"), "planner": self.planner_override,
            }
        n = len(d["vehicles"])
        return {
            "wall_s": wall, "cpu_s": cpu, "inner_wall_s": float(d["wall_time_s"]),
            "vehicle_s": n * float(d["duration_s"]), "sim_s": float(d["duration_s"]),
            "vehicles": [n], "runs": 1, "planner": d.get("planner"),
            "plans": (d.get("planner_stats") or {}).get("plans"), "collisions": d.get("collisions"),
        }


def summarise(samples: list[dict], key: str = "vehicle_s") -> dict:
    rate = [s[key] / s["wall_s"] for s in samples]
    inner = [s[key] / s["inner_wall_s"] for s in samples]
    return {
        "reps": len(samples),
        "rate_median": statistics.median(rate), "rate_min": min(rate), "rate_max": max(rate),
        "inner_rate_median": statistics.median(inner), "inner_rate_min": min(inner),
        "inner_rate_max": max(inner),
        "wall_s_median": statistics.median(s["wall_s"] for s in samples),
        "vehicle_s_per_rep": statistics.median(s[key] for s in samples),
        "sim_s_per_rep": statistics.median(s["sim_s"] for s in samples),
        "cpu_per_wall": sum(s["cpu_s"] for s in samples) / sum(s["wall_s"] for s in samples),
    }


def fmt(x: float) -> str:
    return f"{x:,.0f}" if x >= 100 else f"{x:.3g}"


def main() -> int:
    args = parse_args()
    if args.md_worker:
        return worker_main(args)
    # Everything MetaDrive, Panda3D or pygame print goes to stderr; the table to the real stdout.
    out_fd = os.dup(1)
    sys.stdout.flush()
    os.dup2(2, 1)
    report = os.fdopen(out_fd, "w", encoding="utf-8")

    env_info = environment(args)
    tmp = tempfile.mkdtemp(prefix="mergesim-cmp-md-")
    scenario = os.path.join(tmp, f"platoon_merge_{args.vehicles}.toml")
    toml = subprocess.run([args.bin, "scenario", "platoon", "--vehicles", str(args.vehicles)],
                          capture_output=True, text=True)
    if toml.returncode != 0:
        raise SystemExit(f"merge_sim scenario platoon failed: {toml.stderr}")
    # The generated platoon, with --dt-s's physics step if given.
    text = toml.stdout if args.dt_s is None else with_physics_step(toml.stdout, args.dt_s)
    step = re.search(r"(?m)^dt_s = (\S+)$", text)
    if step is None:
        raise SystemExit("internal: the generated platoon scenario has no dt_s line")
    physics_dt_s = float(step.group(1))
    physics_hz = 1.0 / physics_dt_s
    env_info["mergesim_dt_s"] = physics_dt_s
    with open(scenario, "w", encoding="utf-8") as f:
        f.write(text)
    alt_scenario = None
    if args.also_speed_program:
        if "[sim.planner]" in text or "\n[sim.road]" not in text:
            raise SystemExit("internal: cannot place [sim.planner] in the generated platoon scenario")
        alt_scenario = os.path.join(tmp, f"platoon_merge_{args.vehicles}_{args.also_speed_program}.toml")
        with open(alt_scenario, "w", encoding="utf-8") as f:
            f.write(text.replace(
                "\n[sim.road]",
                f'\n[sim.planner]\nspeed_program = "{args.also_speed_program}"\n\n[sim.road]', 1))

    if args.also_planner:
        # Refused before any MetaDrive work: an unknown name, or one the platoon cannot run.
        check = subprocess.run([args.bin, "run", "--scenario", scenario, "--planner", args.also_planner,
                                "--duration", "0.1", "--no-rrd", "--quiet"], capture_output=True, text=True)
        if check.returncode != 0:
            print(f"error: --also-planner {args.also_planner}: merge_sim refused it:\n{check.stderr.strip()}",
                  file=sys.stderr)
            for name in os.listdir(tmp):
                os.remove(os.path.join(tmp, name))
            os.rmdir(tmp)
            return 2

    log("creating the MetaDrive env (untimed) ...")
    mdv = MetaDrive(args)
    ms = [MergeSim(args.bin, scenario, os.path.join(tmp, f"{k}.json"), k, args) for k in ("run1", "run", "sweep")]
    if alt_scenario:
        ms.append(MergeSim(args.bin, alt_scenario, os.path.join(tmp, "sweep_alt.json"), "sweep", args,
                           key="sweep_alt", note=f", speed_program {args.also_speed_program}"))
    if args.also_planner:
        extra = ("--planner", args.also_planner)
        note = f", planner {args.also_planner}"
        ms.append(MergeSim(args.bin, scenario, os.path.join(tmp, "run1_planner.json"), "run1", args,
                           key="run1_planner", note=note, extra=extra))
        ms.append(MergeSim(args.bin, scenario, os.path.join(tmp, "sweep_planner.json"), "sweep", args,
                           key="sweep_planner", note=note, extra=extra))
    pool = MetaDrivePool(args) if args.md_procs > 1 else None
    variants: list = [("md", mdv)] + ([("md_pool", pool)] if pool else []) + [(m.key, m) for m in ms]
    try:
        log("warm-up (untimed): every MetaDrive scenario's reset + one episode, one run of each mergesim variant")
        mdv.warm_up()
        if pool:
            pool.warm_up()
        first = ms[0].run()
        for m in ms:
            m.duration_s = first["sim_s"]
        for m in ms[1:]:
            m.run()
        samples: dict[str, list[dict]] = {k: [] for k, _ in variants}
        for r in range(args.reps):
            for k, v in variants:
                samples[k].append(v.run())
            log(f"round {r + 1}/{args.reps} done (load average {loadavg()})")
        md_config = mdv.config()
    finally:
        mdv.close()
        if pool:
            pool.close()
        for name in os.listdir(tmp):
            os.remove(os.path.join(tmp, name))
        os.rmdir(tmp)
    load_end = loadavg()

    summ = {k: summarise(samples[k]) for k, _ in variants}
    summ["md_all"] = summarise(samples["md"], "vehicle_s_all")
    base = summ["md"]["rate_median"]
    mds = samples["md"]
    ep_lens = mds[0]["episode_len_s"]
    ends: dict[str, int] = {}
    for e in mds[0]["episode_ends"]:
        ends[e] = ends.get(e, 0) + 1

    e = env_info
    eff = md_config["effective"]
    out = ["### mergesim vs MetaDrive: simulated vehicle-seconds per wall-clock second", ""]
    out.append(f"- date: {e['date']}")
    cores = f"{e['cores']} cores" + (f" ({e['cores_usable']} usable)" if e["cores_usable"] not in (None, e["cores"]) else "")
    out.append(f"- machine: {e['machine']}, {e['cpu_model']}, {cores}; Python {e['python']}; "
               f"load average at start {e['loadavg_at_start']}, at end {load_end}")
    out.append(f"- metadrive-simulator {e['metadrive_simulator']}, panda3d {e['panda3d']} (Bullet), "
               f"gymnasium {e['gymnasium']}, numpy {e['numpy']}")
    dirty = " (working tree has uncommitted changes)" if e["mergesim_tree_dirty"] else ""
    out.append(f"- mergesim checkout {e['mergesim_commit'][:12]}{dirty}; binary {e['merge_sim']} "
               f"({e['merge_sim_version']}, built {e['merge_sim_binary_mtime']})")
    order = ", ".join(v.label for _, v in variants)
    out.append(f"- {args.reps} repetition{'s' if args.reps != 1 else ''} of each, interleaved round by round ({order}), after one untimed warm-up of each")
    uc = ", ".join(f"{k}={v}" for k, v in md_config["user_config"].items())
    out.append(f"- MetaDrive: `MetaDriveEnv(dict({uc}))`; otherwise defaults: map {eff.get('map')} blocks, "
               f"traffic_density {eff.get('traffic_density')}, traffic_mode {eff.get('traffic_mode')}, "
               f"physics_world_step_size {eff.get('physics_world_step_size')} s, decision_repeat "
               f"{eff.get('decision_repeat')}, observation {eff.get('observation')} {eff.get('observation_shape')} "
               f"(lidar {eff['lidar'].get('num_lasers')} beams, {eff['lidar'].get('distance')} m)")
    out.append(f"- MetaDrive episodes: {len(ep_lens)} per repetition (seeds {args.md_seed}–"
               f"{args.md_seed + args.md_episodes - 1}), {min(ep_lens):.1f}–{max(ep_lens):.1f} s long, "
               f"{mds[0]['sim_s']:.1f} s in all; ends: " + ", ".join(f"{k} {n}" for k, n in sorted(ends.items()))
               + f"; at most {mds[0]['max_vehicles']} vehicles driving, {mds[0]['max_vehicles_all']} in the Bullet world"
               + (f"; {mds[0]['capped']} hit the safety cap" if mds[0]["capped"] else ""))
    out.append(f"- mergesim: `merge_sim scenario platoon --vehicles {args.vehicles}` (platoon_merge_{args.vehicles}), "
               f"{ms[0].duration_s:g} s simulated per run, PF-ISO, {physics_hz:g} Hz Rapier "
               f"(dt_s {physics_dt_s:g} s{', set by --dt-s' if args.dt_s is not None else ''}); sweep: {args.sweep_runs} randomised "
               f"instances (--seed 42) on {args.threads} threads"
               + (f"; rows marked \"planner {args.also_planner}\": the same commands with `--planner "
                  f"{args.also_planner}` (every vehicle)" if args.also_planner else ""))
    out.append("")
    out.append("| run | vehicles | simulated s / rep | vehicle-s / rep | vehicle-s per wall s, median (min–max) "
               "| inner timer, median (min–max) | CPU / wall | ratio to MetaDrive (medians) |")
    out.append("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    rows = [("md", mdv.label, f"1–{mds[0]['max_vehicles']} (mean {summ['md']['vehicle_s_per_rep'] / summ['md']['sim_s_per_rep']:.1f})"),
            ("md_all", mdv.label_all, f"≤ {mds[0]['max_vehicles_all']} (mean {summ['md_all']['vehicle_s_per_rep'] / summ['md_all']['sim_s_per_rep']:.1f})")]
    if pool:
        rows.append(("md_pool", pool.label, f"1–{mds[0]['max_vehicles']} per process"))
    rows += [(m.key, m.label, "/".join(str(n) for n in samples[m.key][0]["vehicles"])) for m in ms]
    for key, label, veh in rows:
        s = summ[key]
        rate = f"{fmt(s['rate_median'])} ({fmt(s['rate_min'])}–{fmt(s['rate_max'])})"
        inner = f"{fmt(s['inner_rate_median'])} ({fmt(s['inner_rate_min'])}–{fmt(s['inner_rate_max'])})"
        if key.startswith("md"):
            rate += " ¹"
            inner += " ³"
        else:
            rate += " ²"
            inner += " ⁴"
        ratio = "1" if key == "md" else f"{s['rate_median'] / base:.2f} (inner: {s['inner_rate_median'] / summ['md']['inner_rate_median']:.2f})"
        out.append(f"| {label} | {veh} | {s['sim_s_per_rep']:g} | {s['vehicle_s_per_rep']:,.0f} | {rate} | {inner} "
                   f"| {s['cpu_per_wall']:.2f} | {ratio} |")
    out.append("")
    out.append("¹ MetaDrive: wall time of the env.reset() + env.step() calls (imports and env construction excluded). "
               "² mergesim: wall time of the whole merge_sim process, measured around the subprocess (start-up "
               "included). ³ MetaDrive: env.step() calls only. ⁴ mergesim: the JSON's in-process `wall_time_s`. "
               "Ratio = the row's median / MetaDrive's (driving vehicles) median, of the same column: one "
               "MetaDrive process, so the sweep rows (every core) are to be set beside MetaDrive's processes "
               "at once, as in the sentences below the table. "
               "CPU / wall: 1.00 = one core busy; one MetaDrive process runs on one core.")
    if pool:
        both = summ["sweep"]["rate_median"] / summ["md_pool"]["rate_median"]
        out.append("")
        out.append(f"Every core on both sides: mergesim `sweep` / MetaDrive {args.md_procs} processes = "
                   f"{both:.2f} (medians of the main column).")
        if "sweep_alt" in summ:
            alt = summ["sweep_alt"]["rate_median"] / summ["md_pool"]["rate_median"]
            out.append(f"With speed_program {args.also_speed_program}: mergesim `sweep` / MetaDrive "
                       f"{args.md_procs} processes = {alt:.2f}.")
        if "sweep_planner" in summ:
            alt = summ["sweep_planner"]["rate_median"] / summ["md_pool"]["rate_median"]
            out.append(f"With planner {args.also_planner} in place of PF-ISO: mergesim `sweep` / MetaDrive "
                       f"{args.md_procs} processes = {alt:.2f}.")
    print("\n".join(out), file=report, flush=True)

    if args.json_path:
        doc = {
            "environment": env_info,
            "loadavg_at_end": load_end,
            "metadrive_config": md_config,
            "args": vars(args),
            "variants": {k: {"label": v.label, "command": getattr(v, "cmd", None),
                             "env": ({"RAYON_NUM_THREADS": v.env.get("RAYON_NUM_THREADS")} if isinstance(v, MergeSim) else None),
                             "summary": summ[k], "samples": samples[k]} for k, v in variants},
            "metadrive_all_vehicles_summary": summ["md_all"],
            "ratios_to_metadrive": {k: summ[k]["rate_median"] / base for k in summ if k != "md"},
        }
        with open(args.json_path, "w", encoding="utf-8") as f:
            json.dump(doc, f, indent=2, default=str)
            f.write("\n")
    report.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
