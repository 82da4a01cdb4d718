#!/usr/bin/env python3
"""Paired, interleaved throughput comparison: mergesim vs highway-env's merge-v0.

Run through benches/compare_highway_env.sh, which sets up the venv and the binary; the header
comment there says what each side simulates and what is timed. This helper:

  * highway-env: one `gym.make("merge-v0", render_mode=None)` env (made before any timing),
    ego driven with the constant IDLE action; one repetition = --hwe-episodes episodes, each
    from `reset(seed=hwe_seed + k)` to termination/truncation (the same seeds in every
    repetition, so every repetition does identical work). Timed: reset() and step() calls only.
    Vehicle-seconds = sum over policy steps of len(road.vehicles) x (simulation steps per policy
    step) / simulation_frequency, i.e. len(road.vehicles) summed over every simulation step x
    1/simulation_frequency (the count is checked to be unchanged across each policy step).
  * mergesim: one repetition = one `merge_sim run --scenario S [--planner P] --no-rrd --json OUT
    --quiet` subprocess, timed by this script around the subprocess (process start included);
    the JSON's in-process `wall_time_s` is reported as a second column.
    Vehicle-seconds = len(vehicles) x duration_s.

One untimed warm-up of each variant comes first; then the variants are run interleaved, round
by round (hwe, mergesim, mergesim pf-cs, hwe, ...). Markdown goes to stdout; --json writes all
raw samples.
"""
from __future__ import annotations

import argparse
import re
import importlib.metadata as md
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

from bench_common import loadavg, log, provenance


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bin", required=True, help="path of the merge_sim binary")
    p.add_argument("--root", required=True, help="mergesim checkout (for the git commit)")
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--scenario", default="urgent_merge")
    p.add_argument("--planner", default=None)
    p.add_argument("--vehicle-model", default=None,
                   help="vehicle model of every mergesim car (merge_sim run --vehicle-model)")
    p.add_argument("--dt-s", default=None,
                   help="comma-separated physics steps (s): one mergesim row (and PF-CS row) per value, "
                        "each from a copy of the scenario with [sim] dt_s replaced; default: the scenario's own")
    p.add_argument("--hwe-episodes", type=int, default=10)
    p.add_argument("--hwe-seed", type=int, default=0)
    p.add_argument("--hwe-max-policy-steps", type=int, default=1000,
                   help="safety cap per episode (merge-v0 has no time limit of its own)")
    p.add_argument("--json", dest="json_path", default=None)
    a = p.parse_args()
    if a.reps < 1 or a.hwe_episodes < 1 or a.hwe_max_policy_steps < 1:
        p.error("--reps, --hwe-episodes and --hwe-max-policy-steps must be >= 1")
    return a


def environment(args: argparse.Namespace) -> dict:
    return provenance(args.root, args.bin, {
        "highway_env": md.version("highway-env"),
        "gymnasium": md.version("gymnasium"),
        "numpy": md.version("numpy"),
    })


class HighwayEnvMerge:
    """highway-env merge-v0, IDLE ego, episodes to termination."""

    def __init__(self, args: argparse.Namespace) -> None:
        import gymnasium as gym
        import highway_env  # noqa: F401  (registers the envs)

        with warnings.catch_warnings():
            # "merge-v0 is out of date, consider v1": v1 only adds neighbour look-ups across
            # connected lanes; the brief asks for merge-v0.
            warnings.simplefilter("ignore")
            self.env = gym.make("merge-v0", render_mode=None)
        self.u = self.env.unwrapped
        self.cfg = self.u.config
        self.sim_hz = float(self.cfg["simulation_frequency"])
        self.policy_hz = float(self.cfg["policy_frequency"])
        # AbstractEnv._simulate runs int(sim // policy) simulation steps per env.step().
        self.frames = int(self.cfg["simulation_frequency"] // self.cfg["policy_frequency"])
        self.idle = self.u.action_type.actions_indexes["IDLE"]
        self.episodes = args.hwe_episodes
        self.seed0 = args.hwe_seed
        self.max_steps = args.hwe_max_policy_steps
        self.label = "highway-env merge-v0 (IDLE ego)"

    def config(self) -> dict:
        keep = ("simulation_frequency", "policy_frequency", "other_vehicles_type", "observation", "action")
        c = {k: self.cfg[k] for k in keep if k in self.cfg}
        c.update({
            "env_id": "merge-v0",
            "render_mode": None,
            "ego_action": "IDLE (constant)",
            "simulation_steps_per_policy_step": self.frames,
            "episodes_per_rep": self.episodes,
            "seeds": [self.seed0, self.seed0 + self.episodes - 1],
            "episode_end": "termination/truncation (crash or ego x > 370 m); "
                           f"safety cap {self.max_steps} policy steps",
        })
        return c

    def run(self, episodes: int | None = None, seed0: int | None = None) -> dict:
        episodes = self.episodes if episodes is None else episodes
        seed0 = self.seed0 if seed0 is None else seed0
        env, u, idle, frames = self.env, self.u, self.idle, self.frames
        dt_sim = 1.0 / self.sim_hz
        pc = time.perf_counter
        cpu0 = time.process_time()
        t_reset = t_step = 0.0
        veh_s = sim_s = 0.0
        ep_len_s, ep_vehicles = [], set()
        crashed = capped = 0
        count_changed = False
        for k in range(episodes):
            t0 = pc()
            env.reset(seed=seed0 + k)
            t_reset += pc() - t0
            steps = 0
            while True:
                n = len(u.road.vehicles)
                t0 = pc()
                _, _, terminated, truncated, _ = env.step(idle)
                t_step += pc() - t0
                if len(u.road.vehicles) != n:
                    count_changed = True
                ep_vehicles.add(n)
                veh_s += n * frames * dt_sim
                sim_s += frames * dt_sim
                steps += 1
                if terminated or truncated:
                    break
                if steps >= self.max_steps:
                    capped += 1
                    break
            ep_len_s.append(steps * frames * dt_sim)
            crashed += bool(u.vehicle.crashed)
        cpu = time.process_time() - cpu0
        wall = t_reset + t_step
        return {
            "wall_s": wall,
            "cpu_s": cpu,  # process CPU time over the whole loop (bookkeeping included)
            "inner_wall_s": t_step,  # steps only, resets excluded
            "reset_s": t_reset,
            "vehicle_s": veh_s,
            "sim_s": sim_s,
            "vehicles": sorted(ep_vehicles),
            "episode_len_s": ep_len_s,
            "ego_crashed": crashed,
            "capped": capped,
            "vehicle_count_changed_within_step": count_changed,
        }


def scenario_with_dt(bin_path: str, scenario: str, dt_s: float, path: str) -> str:
    """Writes the scenario (a TOML file, or a built-in by `merge_sim scenario show`) to `path`
    with its `[sim]` table's dt_s set to `dt_s`; returns `path`."""
    if os.path.isfile(scenario):
        with open(scenario, encoding="utf-8") as f:
            text = f.read()
    else:
        proc = subprocess.run([bin_path, "scenario", "show", scenario], capture_output=True, text=True)
        if proc.returncode != 0:
            raise SystemExit(f"merge_sim scenario show {scenario} failed: {proc.stderr}")
        text = proc.stdout
    sim = re.search(r"^\[sim\]\s*$", text, flags=re.M)
    if sim is None:
        raise SystemExit(f"{scenario}: no [sim] table to set dt_s in")
    head, body = text[: sim.end()], text[sim.end():]
    table_end = re.search(r"^\[", body, flags=re.M)
    table, rest = (body[: table_end.start()], body[table_end.start():]) if table_end else (body, "")
    table, n = re.subn(r"^dt_s\s*=.*$", f"dt_s = {dt_s!r}", table, count=1, flags=re.M)
    if n == 0:
        table = f"\ndt_s = {dt_s!r}" + table
    with open(path, "w", encoding="utf-8") as f:
        f.write(head + table + rest)
    return path


class MergeSim:
    def __init__(self, args: argparse.Namespace, planner: str | None, tmp: str, tag: str,
                 dt_s: float | None = None) -> None:
        self.bin = args.bin
        self.scenario = args.scenario
        self.planner = planner
        self.dt_s = dt_s
        self.out = os.path.join(tmp, f"{tag}.json")
        source = self.scenario
        if dt_s is not None:
            source = scenario_with_dt(self.bin, self.scenario, dt_s, os.path.join(tmp, f"{tag}.toml"))
        self.cmd = [self.bin, "run", "--scenario", source, "--no-rrd", "--json", self.out, "--quiet"]
        if planner:
            self.cmd += ["--planner", planner]
        self.vehicle_model = args.vehicle_model
        if self.vehicle_model:
            self.cmd += ["--vehicle-model", self.vehicle_model]
        self.label = f"mergesim {self.scenario} ({planner or 'scenario default'}{self._model()})"

    def _model(self) -> str:
        model = f", {self.vehicle_model} vehicles" if self.vehicle_model else ""
        step = f", dt {self.dt_s * 1e3:g} ms" if self.dt_s is not None else ""
        return model + step

    def run(self) -> dict:
        if os.path.exists(self.out):
            os.remove(self.out)
        ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(self.cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        wall = time.perf_counter() - t0
        ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)
        if proc.returncode != 0:
            raise SystemExit(f"merge_sim failed ({proc.returncode}): {' '.join(self.cmd)}\n{proc.stderr}")
        with open(self.out, encoding="utf-8") as f:
            d = json.load(f)
        n = len(d["vehicles"])
        planner = d.get("planner")
        if planner:
            self.label = f"mergesim {self.scenario} ({planner}{self._model()})"
        per_vehicle = sum(float(v.get("duration_s", d["duration_s"])) for v in d["vehicles"])
        return {
            "wall_s": wall,  # process wall time, start-up included
            "cpu_s": cpu,  # user + system CPU time of the child process
            "inner_wall_s": float(d["wall_time_s"]),  # in-process, from the JSON
            "vehicle_s": n * float(d["duration_s"]),
            "sim_s": float(d["duration_s"]),
            "vehicles": [n],
            "planner": planner,
            "collisions": d.get("collisions"),
            "sum_vehicle_duration_s": per_vehicle,
        }


def summarise(samples: list[dict]) -> dict:
    rate = [s["vehicle_s"] / s["wall_s"] for s in samples]
    inner = [s["vehicle_s"] / s["inner_wall_s"] for s in samples]
    return {
        "reps": len(samples),
        "rate_median": statistics.median(rate),
        "rate_min": min(rate),
        "rate_max": max(rate),
        "inner_rate_median": statistics.median(inner),
        "inner_rate_min": min(inner),
        "inner_rate_max": max(inner),
        "wall_s_median": statistics.median(s["wall_s"] for s in samples),
        "vehicle_s_per_rep": statistics.median(s["vehicle_s"] for s in samples),
        "sim_s_per_rep": statistics.median(s["sim_s"] for s in samples),
        "vehicles": sorted({n for s in samples for n in s["vehicles"]}),
        "cpu_per_wall": sum(s["cpu_s"] for s in samples) / sum(s["wall_s"] for s in samples),
    }


def fmt(x: float) -> str:
    return f"{x:,.0f}" if x >= 100 else f"{x:.3g}"


def main() -> int:
    args = parse_args()
    env_info = environment(args)
    hwe = HighwayEnvMerge(args)
    tmp = tempfile.mkdtemp(prefix="mergesim-cmp-")
    try:
        steps = [float(x) for x in args.dt_s.split(",")] if args.dt_s else [None]
        variants: list = [("hwe", hwe)]
        for k, dt_s in enumerate(steps):
            suffix = "" if dt_s is None else f"_dt{k}"
            main_variant = MergeSim(args, args.planner, tmp, f"ms{suffix}", dt_s)
            variants.append((f"ms{suffix}", main_variant))
            if args.planner != "pf-cs":
                variants.append((f"ms_pf_cs{suffix}", MergeSim(args, "pf-cs", tmp, f"ms_pf_cs{suffix}", dt_s)))

        log("warm-up (untimed): one highway-env episode and one run of each mergesim variant")
        hwe.run(episodes=1, seed0=args.hwe_seed + 10_000)
        for key, v in variants[1:]:
            v.run()
        # A default-planner variant may have resolved to pf-cs itself: drop the duplicate.
        labels = set()
        unique = []
        for key, v in variants:
            if v is hwe or v.label not in labels:
                unique.append((key, v))
                labels.add(getattr(v, "label", None))
        variants = unique

        samples: dict[str, list[dict]] = {key: [] for key, _ in variants}
        for r in range(args.reps):
            for key, v in variants:
                samples[key].append(v.run())
            log(f"round {r + 1}/{args.reps} done")
    finally:
        for name in os.listdir(tmp):
            os.remove(os.path.join(tmp, name))
        os.rmdir(tmp)

    summ = {key: summarise(samples[key]) for key, _ in variants}
    base = summ["hwe"]["rate_median"]
    hs = samples["hwe"]
    ep_lens = [x for s in hs[:1] for x in s["episode_len_s"]]  # identical in every rep (same seeds)

    e = env_info
    out = []
    out.append("### mergesim vs highway-env: simulated vehicle-seconds per wall-clock second")
    out.append("")
    out.append(f"- date: {e['date']}")
    cores = f"{e['cores']} cores" + (f" ({e['cores_usable']} usable)" if e['cores_usable'] not in (None, e['cores']) else "")
    out.append(f"- machine: {e['machine']}, {e['cpu_model']}, {cores}; Python {e['python']}; "
               f"load average at start {e['loadavg_at_start']}")
    out.append(f"- highway-env {e['highway_env']}, gymnasium {e['gymnasium']}, numpy {e['numpy']}")
    dirty = " (working tree has uncommitted changes)" if e["mergesim_tree_dirty"] else ""
    out.append(f"- mergesim commit {e['mergesim_commit'][:12]}{dirty}; {e['merge_sim_version']}, "
               f"binary built {e['merge_sim_binary_mtime']}")
    order = ", ".join(v.label for _, v in variants)
    out.append(f"- {args.reps} repetitions of each, interleaved round by round ({order}), "
               "after one untimed warm-up of each")
    c = hwe.config()
    out.append(f"- highway-env config: merge-v0 defaults, simulation_frequency {c['simulation_frequency']} Hz, "
               f"policy_frequency {c['policy_frequency']} Hz, other vehicles {c['other_vehicles_type'].rsplit('.', 1)[-1]}, "
               f"observation {c['observation'].get('type')}, action {c['action'].get('type')} = IDLE always, "
               f"render_mode None; one repetition = {args.hwe_episodes} episodes (seeds "
               f"{args.hwe_seed}–{args.hwe_seed + args.hwe_episodes - 1}) each run to termination")
    out.append(f"- highway-env episodes: {len(ep_lens)} per repetition, {min(ep_lens):g}–{max(ep_lens):g} s long "
               f"(mean {statistics.mean(ep_lens):.2g} s); the IDLE ego crashed in {hs[0]['ego_crashed']} of them"
               + (f"; {hs[0]['capped']} hit the safety cap" if hs[0]["capped"] else ""))
    out.append("")
    out.append("| run | vehicles | simulated s / rep | vehicle-s / rep | vehicle-s per wall s, median (min–max) "
               "| inner timer, median (min–max) | ratio to highway-env (medians) |")
    out.append("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for key, v in variants:
        s = summ[key]
        veh = "/".join(str(n) for n in s["vehicles"])
        rate = f"{fmt(s['rate_median'])} ({fmt(s['rate_min'])}–{fmt(s['rate_max'])})"
        inner = f"{fmt(s['inner_rate_median'])} ({fmt(s['inner_rate_min'])}–{fmt(s['inner_rate_max'])})"
        if key == "hwe":
            ratio = "1"
            rate += " ¹"
            inner += " ³"
        else:
            ratio = (f"{s['rate_median'] / base:.2f} (in-process: {s['inner_rate_median'] / base:.2f})")
            rate += " ²"
            inner += " ⁴"
        out.append(f"| {v.label} | {veh} | {s['sim_s_per_rep']:g} | {s['vehicle_s_per_rep']:g} | {rate} | {inner} | {ratio} |")
    out.append("")
    out.append("¹ highway-env: wall time of the env.reset() + env.step() calls (package import and gym.make "
               "excluded). "
               "² mergesim: wall time of the whole `merge_sim run --no-rrd --json OUT --quiet` process, measured "
               "around the subprocess (start-up included). "
               "³ highway-env: env.step() calls only (resets excluded). "
               "⁴ mergesim: the JSON's in-process `wall_time_s`. "
               "Ratio = mergesim median / highway-env median of the main column ¹.")
    cpu = ", ".join(f"{v.label} {summ[key]['cpu_per_wall']:.2f}" for key, v in variants)
    out.append("")
    out.append(f"CPU time / wall time (1.00 = one core busy): {cpu}.")
    print("\n".join(out))

    changed = any(s["vehicle_count_changed_within_step"] for s in hs)
    if changed:
        print("\nWarning: highway-env's vehicle count changed within a policy step; "
              "vehicle-seconds used the count at the start of each policy step.")
    for key, v in variants[1:]:
        for s in samples[key]:
            if abs(s["sum_vehicle_duration_s"] - s["vehicle_s"]) > 0.05 * s["vehicle_s"]:
                print(f"\nNote: {v.label}: sum of per-vehicle duration_s ({s['sum_vehicle_duration_s']:g}) "
                      f"differs from vehicles x duration_s ({s['vehicle_s']:g}).")
                break

    if args.json_path:
        doc = {
            "environment": env_info,
            "highway_env_config": hwe.config(),
            "reps": args.reps,
            "scenario": args.scenario,
            "planner": args.planner,
            "vehicle_model": args.vehicle_model,
            "dt_s": args.dt_s,
            "variants": {key: {"label": v.label, "command": getattr(v, "cmd", None),
                               "summary": summ[key], "samples": samples[key]} for key, v in variants},
            "ratios_to_highway_env": {key: {"process": summ[key]["rate_median"] / base,
                                            "in_process": summ[key]["inner_rate_median"] / base}
                                      for key, _ in variants[1:]},
        }
        with open(args.json_path, "w", encoding="utf-8") as f:
            json.dump(doc, f, indent=2, default=str)
            f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
