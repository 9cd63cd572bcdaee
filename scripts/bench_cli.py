#!/usr/bin/env python3
"""CLI-level benchmarks of the performance work, side by side with an anchor binary.

usage: scripts/bench_cli.py [--anchor OLD_RTBAKE] [--runs N] [RTBAKE]

Times whole commands (process start to exit, output written to a scratch directory) as a user's pipeline runs
them: MLAA AreaMap513 with `--format bin` and with every format, the MLAA generator with 1 and 2 rayon threads,
the default bake of the assets both binaries know, and its verify. Every job runs RUNS times (default 7, at least 3) alternating between the
binary under test and the anchor, so both see the same machine load; the 1- and 2-thread runs of a pair alternate
in the same rounds, each binary's on their own (each run starts after an untimed `sync`); it prints the median with min-max and the
anchor/new ratio of wall and of CPU time (user + sys; the wall time of large outputs is bound by the disk
flush). RTBAKE defaults to target/release/rtbake. Nothing here is a test: figures are for the README
and the issue notes.
"""
import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

MLAA_1023 = ["aa", "mlaa-v1.4", "--max-distance", "1023", "--format", "bin"]
# Groups of (name, argv after the binary, env overrides). A group of one job alternates the binaries in every round;
# a thread pair runs each binary's rounds on their own (1 thread, 2 threads, 1 thread, …), so drift of the shared
# machine falls on both sides of a 1 -> 2 ratio and neither side follows the other binary's run (whose large frees
# and flushes leave the kernel more work for whichever run comes next).
JOB_GROUPS = [
    [("aa mlaa-v1.4 N=513 --format bin", ["aa", "mlaa-v1.4", "--max-distance", "513", "--format", "bin"], {})],
    [("aa mlaa-v1.4 N=513 all formats", ["aa", "mlaa-v1.4", "--max-distance", "513", "--format", "bin,dds,ktx2,png"],
      {})],
    [("aa mlaa-v1.4 N=1023 bin, 1 thread", MLAA_1023, {"RAYON_NUM_THREADS": "1"}),
     ("aa mlaa-v1.4 N=1023 bin, 2 threads", MLAA_1023, {"RAYON_NUM_THREADS": "2"})],
    [("bake (common assets), 1 thread", ["bake", "--quiet"], {"RAYON_NUM_THREADS": "1"}),
     ("bake (common assets), 2 threads", ["bake", "--quiet"], {"RAYON_NUM_THREADS": "2"})],
    [("verify", ["verify"], {})],
]

COMMON_ASSETS = []


def asset_names(binary):
    r = subprocess.run([binary, "assets"], capture_output=True, text=True, check=True)
    return [line.split()[0] for line in r.stdout.splitlines() if line.strip()]


def run_once(binary, argv, env, scratch):
    out = os.path.join(scratch, "out")
    if argv[0] == "verify":
        argv = ["verify", "--dir", os.path.join(scratch, "baked")]
    elif argv[0] == "bake":
        shutil.rmtree(os.path.join(scratch, "bakeout"), ignore_errors=True)
        argv = argv + COMMON_ASSETS + ["--out", os.path.join(scratch, "bakeout")]
    else:
        shutil.rmtree(out, ignore_errors=True)
        argv = argv + ["--out", out]
    e = dict(os.environ, **env)
    # Untimed: flush what earlier runs left dirty (the other binary's files, the removed outputs), so no command
    # waits in its own fsync for another run's data (ext4's ordered journal commits every dirty file it touches).
    os.sync()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    r = subprocess.run([binary] + argv, env=e, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    dt = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        sys.exit(f"{binary} {' '.join(argv)} failed: {r.stderr.decode()[-500:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return dt, cpu


def fmt(ts):
    walls = [w for w, _ in ts]
    cpu = statistics.median(c for _, c in ts)
    return f"{statistics.median(walls):7.3f} s ({min(walls):.3f}-{max(walls):.3f}) cpu {cpu:6.3f} s"


def med(ts, k=0):
    return statistics.median(t[k] for t in ts)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary", nargs="?", default="target/release/rtbake")
    ap.add_argument("--anchor", help="rtbake binary to compare with (e.g. a build of the previous commit)")
    ap.add_argument("--runs", type=int, default=7)
    args = ap.parse_args()
    runs = max(3, args.runs)
    bins = [("new", args.binary)] + ([("anchor", args.anchor)] if args.anchor else [])
    # Bake and verify the assets both binaries know (a newer rtbake may have more), so the work is the same.
    common = set(asset_names(args.binary))
    for _, b in bins[1:]:
        common &= set(asset_names(b))
    COMMON_ASSETS.extend(sorted(common))
    print(f"rtbake bench_cli: median (min-max) of {runs} runs, {os.cpu_count()} logical CPUs; binaries: "
          + ", ".join(f"{n}={b}" for n, b in bins))
    with tempfile.TemporaryDirectory(dir=os.environ.get("BENCH_DIR")) as scratch:
        # verify needs a bake of the same binary: each binary verifies its own.
        results = {}
        for group in JOB_GROUPS:
            times = {name: {n: [] for n, _ in bins} for name, _, _ in group}
            order = [[n_b] for n_b in bins] if len(group) > 1 else [bins]
            for binaries in order:
                for _ in range(runs):
                    for name, argv, env in group:
                        for n, b in binaries:
                            s = os.path.join(scratch, n)
                            os.makedirs(s, exist_ok=True)
                            if argv[0] == "verify" and not os.path.exists(os.path.join(s, "baked")):
                                subprocess.run(
                                    [b, "bake", "--quiet", *COMMON_ASSETS, "--out", os.path.join(s, "baked")],
                                    check=True,
                                )
                            times[name][n].append(run_once(b, argv, env, s))
            for name, _, _ in group:
                t = times[name]
                results[name] = t
                line = f"{name:<38} new {fmt(t['new'])}"
                if args.anchor:
                    ratio = med(t["anchor"]) / med(t["new"])
                    cpu_ratio = med(t["anchor"], 1) / max(med(t["new"], 1), 1e-9)
                    line += f" | anchor {fmt(t['anchor'])} | anchor/new wall {ratio:5.2f}x cpu {cpu_ratio:5.2f}x"
                print(line, flush=True)
        for n, _ in bins:
            one = med(results["aa mlaa-v1.4 N=1023 bin, 1 thread"][n])
            two = med(results["aa mlaa-v1.4 N=1023 bin, 2 threads"][n])
            b1 = med(results["bake (common assets), 1 thread"][n])
            b2 = med(results["bake (common assets), 2 threads"][n])
            print(f"{n}: 1 -> 2 threads: MLAA N=1023 {one / two:.2f}x, full bake {b1 / b2:.2f}x")


if __name__ == "__main__":
    main()
