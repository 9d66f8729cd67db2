#!/usr/bin/env python3
"""A population of cars and roads the CCU's brake functions were not tuned on (docs/vehicle.md,
"A population of cars"): straight full-pedal stops of the sedan laden with 0-450 kg placed
anywhere from the front seats to the boot (mass, centre of gravity and yaw inertia change; the
CCU's own car model stays the nominal sedan's, as a production CCU knows no payload), on dry, wet,
snow and ice with each surface's grip drawn within +-10 % of its nominal, from 60-140 km/h.
Seeded: the same --seed draws the same cars. Measurement only: never tune on it.

  scripts/vehicle-population.py OUT [--draws N] [--seed S] [--jobs J]

Writes OUT/scenarios/*.yaml and OUT/vehicles/*.yaml (the drawn cars), runs each in process
(bbw_vehicle_inproc, J at a time, progress and time left on stderr; a run whose summary.json is
there already is not run again, so an interrupted population resumes), and prints a table per
draw and, per surface, the median / p90 / worst of the distance ratio and of the longest wheel
lock above 15 km/h, the worst draw named. OUT/population.json holds every row.
"""
import argparse
import concurrent.futures
import json
import math
import os
import random
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SURFACES = {  # name: nominal mu_scale of config/vehicle/sedan.yaml
    "dry": 0.8518,
    "wet": 0.6815,
    "snow": 0.2556,
    "ice": 0.0852,
}
NOMINAL = {"mass_kg": 1093.3, "yaw_inertia_kg_m2": 1791.6, "cg_to_front_axle_m": 1.1562,
           "cg_to_rear_axle_m": 1.4227, "cg_height_m": 0.5749}


def draw(seed, i):
    """Draw i of the population: a laden sedan on a surface, at a speed."""
    rng = random.Random(seed * 1000003 + i)
    surface = list(SURFACES)[i % len(SURFACES)]
    d = {
        "index": i,
        "surface": surface,
        "grip": round(rng.uniform(0.9, 1.1), 3),
        "speed_km_h": rng.randint(60, 140),
        "payload_kg": round(rng.uniform(0.0, 450.0), 1),
        # Where the payload sits, behind the front axle (front seats about 0.9 m, boot about 2.6 m)
        # and how high.
        "payload_x_m": round(rng.uniform(0.9, 2.6), 3),
        "payload_h_m": round(rng.uniform(0.45, 0.75), 3),
        "scenario_seed": rng.randint(1, 10**6),
    }
    n = NOMINAL
    m0, a0 = n["mass_kg"], n["cg_to_front_axle_m"]
    L = a0 + n["cg_to_rear_axle_m"]
    m = m0 + d["payload_kg"]
    a = (m0 * a0 + d["payload_kg"] * d["payload_x_m"]) / m
    h = (m0 * n["cg_height_m"] + d["payload_kg"] * d["payload_h_m"]) / m
    # Parallel axes: the empty car's inertia about the new centre, plus the payload's (a point).
    iz = n["yaw_inertia_kg_m2"] + m0 * (a - a0) ** 2 + d["payload_kg"] * (d["payload_x_m"] - a) ** 2
    d.update({"mass_kg": round(m, 2), "cg_to_front_axle_m": round(a, 4), "cg_to_rear_axle_m": round(L - a, 4),
              "cg_height_m": round(h, 4), "yaw_inertia_kg_m2": round(iz, 1)})
    return d


def replace_key(text, key, value, path):
    """Replaces `  key: ...` (its first occurrence) keeping the rest of the line's comment out."""
    lines = text.split("\n")
    for k, line in enumerate(lines):
        stripped = line.lstrip()
        if stripped.startswith(key + ":"):
            indent = line[: len(line) - len(stripped)]
            lines[k] = f"{indent}{key}: {value}"
            return "\n".join(lines)
    raise SystemExit(f"vehicle-population: {path}: no key '{key}' to replace")


def write_draw(out, d):
    sedan = os.path.join(ROOT, "config/vehicle/sedan.yaml")
    text = open(sedan).read()
    for key in ("mass_kg", "yaw_inertia_kg_m2", "cg_to_front_axle_m", "cg_to_rear_axle_m", "cg_height_m"):
        text = replace_key(text, key, d[key], sedan)
    mu = SURFACES[d["surface"]] * d["grip"]
    marker = "surfaces:\n"
    if marker not in text:
        raise SystemExit(f"vehicle-population: {sedan}: no 'surfaces:' list")
    text = text.replace(marker, marker + f"  - {{name: drawn, mu_scale: {mu:.5f}, stiffness_scale: {mu:.5f}}}\n", 1)
    name = f"vp_{d['index']:03d}_{d['surface']}"
    vehicle = os.path.join(out, "vehicles", name + ".yaml")
    with open(vehicle, "w") as f:
        f.write("# Drawn by scripts/vehicle-population.py (docs/vehicle.md): " + json.dumps(d) + "\n" + text)
    # Long enough to stop: v / (0.8 mu g) plus the pedal and a margin.
    v = d["speed_km_h"] / 3.6
    duration = math.ceil(v / (0.8 * SURFACES[d["surface"]] / SURFACES["dry"] * d["grip"] * 9.81) + 3.0)
    base = os.path.join(ROOT, "config/scenarios/vehicle")
    scenario = f"""# Drawn by scripts/vehicle-population.py (docs/vehicle.md): measurement only.
name: {name}
seed: {d['scenario_seed']}
duration_s: {duration}.0
corners: {base}/corners/calipers_28C.yaml
vehicle: {vehicle}
brake_control: {ROOT}/config/vehicle/brake_control.yaml
initial_speed_km_h: {d['speed_km_h']}
road: {{surface: drawn, grade_percent: 0.0, ambient_C: 20.0, patches: []}}
pedal_travel: [0.0, 0.0, 0.2, 0.0, 0.3, 1.0, {duration}.0, 1.0]
driver: {{path_radius_m: 0.0, preview_s: 0.8, gain_rad_per_m: 0.02, yaw_rate_gain_s: 0.1, reaction_s: 0.15, lag_s: 0.1, max_rate_rad_s: 0.6, max_steer_rad: 0.3}}
disc_temperature_C: [40.0, 40.0, 40.0, 40.0]
processes: [ccu, FL, FR, RL, RR, vehicle, pedal]
"""
    path = os.path.join(out, "scenarios", name + ".yaml")
    with open(path, "w") as f:
        f.write(scenario)
    return name, path


def run_one(binary, out, name, path):
    run_dir = os.path.join(out, "runs", name)
    summary = os.path.join(run_dir, "summary.json")
    if not os.path.exists(summary):
        r = subprocess.run([binary, path, "--out", run_dir, "--no-plots"], capture_output=True, text=True)
        if r.returncode != 0 or not os.path.exists(summary):
            raise RuntimeError(f"{name}: bbw_vehicle_inproc exited {r.returncode}: {r.stderr.strip()[-400:]}")
    return json.load(open(summary))["vehicle"]


def quantile(xs, q):
    s = sorted(xs)
    return s[min(len(s) - 1, max(0, math.ceil(q * len(s)) - 1))]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--draws", type=int, default=48)
    ap.add_argument("--seed", type=int, default=1501)
    ap.add_argument("--jobs", type=int, default=2)
    o = ap.parse_args()
    if o.draws < 1 or o.jobs < 1:
        raise SystemExit("vehicle-population: --draws and --jobs must be at least 1")
    binary = os.path.join(os.environ.get("BBW_BUILD_DIR", os.path.join(ROOT, "build")), "bin", "bbw_vehicle_inproc")
    if not os.access(binary, os.X_OK):
        raise SystemExit(f"vehicle-population: {binary} not found (./bbw build first)")
    for sub in ("scenarios", "vehicles", "runs"):
        os.makedirs(os.path.join(o.out, sub), exist_ok=True)
    draws = [draw(o.seed, i) for i in range(o.draws)]
    jobs = [(d, *write_draw(o.out, d)) for d in draws]
    rows, t0, done = {}, time.monotonic(), 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=o.jobs) as pool:
        futures = {pool.submit(run_one, binary, o.out, name, path): (d, name) for d, name, path in jobs}
        for fut in concurrent.futures.as_completed(futures):
            d, name = futures[fut]
            rows[name] = (d, fut.result())
            done += 1
            elapsed = time.monotonic() - t0
            left = elapsed / done * (len(jobs) - done)
            print(f"\r{done}/{len(jobs)} stops, {elapsed:.0f} s, about {left:.0f} s left ", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    table = []
    print("| draw | surface | grip | km/h | payload kg at m | cg front m / h m | stop m | ideal m | ratio | longest lock s | max lateral m | epsilon |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in sorted(rows):
        d, v = rows[name]
        lock = max(v["longest_wheel_lock_s"].values())
        eps = v.get("adhesion_utilisation")
        table.append({"name": name, **d, "stopping_distance_m": v["stopping_distance_m"], "ideal_m": v["ideal_stopping_distance_m"],
                      "distance_ratio": v["distance_ratio"], "longest_lock_s": lock,
                      "max_lateral_deviation_m": v["max_lateral_deviation_m"], "epsilon": eps})
        ratio = v["distance_ratio"]
        print(f"| {name} | {d['surface']} | {d['grip']:.3f} | {d['speed_km_h']} | {d['payload_kg']:.0f} at {d['payload_x_m']:.2f} | "
              f"{d['cg_to_front_axle_m']:.3f} / {d['cg_height_m']:.3f} | {v['stopping_distance_m']:.2f} | "
              f"{v['ideal_stopping_distance_m']:.2f} | {'-' if ratio is None else f'{ratio:.3f}'} | {lock:.3f} | "
              f"{v['max_lateral_deviation_m']:.2f} | {'-' if eps is None else f'{eps:.3f}'} |")
    print()
    print("| surface | stops | distance ratio median / p90 / worst (draw) | longest lock median / p90 / worst (draw) | locks > 100 ms | max lateral worst (draw) |")
    print("|---|---|---|---|---|---|")
    for surface in SURFACES:
        rs = [r for r in table if r["surface"] == surface]
        if not rs:
            continue
        stopped = [r for r in rs if r["distance_ratio"] is not None]
        worst_ratio = max(stopped, key=lambda r: r["distance_ratio"]) if stopped else None
        worst_lock = max(rs, key=lambda r: r["longest_lock_s"])
        worst_lat = max(rs, key=lambda r: r["max_lateral_deviation_m"])
        ratio_txt = "no stop" if not stopped else (
            f"{quantile([r['distance_ratio'] for r in stopped], 0.5):.3f} / {quantile([r['distance_ratio'] for r in stopped], 0.9):.3f} / "
            f"{worst_ratio['distance_ratio']:.3f} ({worst_ratio['name']})")
        locks = [r["longest_lock_s"] for r in rs]
        print(f"| {surface} | {len(rs)} ({len(rs) - len(stopped)} not stopped) | {ratio_txt} | "
              f"{quantile(locks, 0.5):.3f} / {quantile(locks, 0.9):.3f} / {worst_lock['longest_lock_s']:.3f} ({worst_lock['name']}) | "
              f"{sum(1 for x in locks if x > 0.1)} | {worst_lat['max_lateral_deviation_m']:.2f} ({worst_lat['name']}) |")
    with open(os.path.join(o.out, "population.json"), "w") as f:
        json.dump({"seed": o.seed, "draws": o.draws, "rows": table}, f, indent=1)


if __name__ == "__main__":
    main()
