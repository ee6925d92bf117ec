#!/usr/bin/env python3
"""tt_dask.py -- a tiled terratin run on Dask distributed (docs/scale.md).

Plans the tiles (`terratin tiles plan`), submits every tile to a
distributed.Client as its own `terratin tiles run` process, waits, and
merges (`terratin tiles merge`): the same TIN as `terratin simplify
-tile_size` with the same options. Workers need the same file system paths
as the driver (a shared file system on a real cluster) and terratin.

  tt_dask.py [--scheduler ADDR | --workers N] [--terratin PATH]
             [--plan PLAN.json] [--keep] [--overwrite] [--stats FILE]
             DEM OUT.gpkg -max_error E -tile_size N [simplify options]

The options that shape the TIN go into the plan; those of the output
(-of, -lco, -dsco, -nln, -layers, -nostyle, -obj_local, -t_srs), which a
plan never carries, go to `terratin tiles merge`.

Without --scheduler a LocalCluster of N worker processes (one thread each)
is started with every socket (its HTTP servers too) on 127.0.0.1. Exit codes: 0 done, 1 a tile or
the merge failed (nothing written), 2 usage, 3 distributed is missing.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time


# simplify's output options and whether each takes a value: `tiles merge`
# takes them on its own command line (a plan refuses them)
OUTPUT_OPTIONS = {"-of": True, "-f": True, "-lco": True, "-dsco": True,
                  "-nln": True, "-layers": True, "-t_srs": True,
                  "-nostyle": False, "-obj_local": False}


def split_options(opts):
    """simplify's options as (the plan's, the merge's)."""
    plan, merge = [], []
    i = 0
    while i < len(opts):
        w = opts[i]
        name = w[1:] if w.startswith("--") else w
        if name.lower() in OUTPUT_OPTIONS:
            n = 2 if OUTPUT_OPTIONS[name.lower()] else 1
            merge += opts[i:i + n]
            i += n
        else:
            plan.append(w)
            i += 1
    return plan, merge


def run_tile(terratin, plan, k):
    """One tile in its own process on a worker: seconds, peak RSS, pid."""
    t0 = time.monotonic()
    with tempfile.TemporaryFile() as err:
        p = subprocess.Popen([terratin, "tiles", "run", plan, str(k),
                              "-overwrite"], stdout=subprocess.DEVNULL,
                             stderr=err)
        _, status, ru = os.wait4(p.pid, 0)
        p.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        msg = err.read().decode(errors="replace").strip()
    if p.returncode != 0:
        raise RuntimeError("tile %d: %s (exit %d)" % (k, msg, p.returncode))
    return {"tile": k, "seconds": time.monotonic() - t0,
            "max_rss_kib": ru.ru_maxrss, "worker_pid": os.getpid()}


def main(argv):
    ap = argparse.ArgumentParser(
        description="terratin tiles on Dask distributed", usage=__doc__)
    ap.add_argument("--scheduler", help="a scheduler's address (tcp://...)")
    ap.add_argument("--workers", type=int, default=2,
                    help="LocalCluster worker processes (no --scheduler)")
    ap.add_argument("--terratin", default=os.environ.get("TT_TERRATIN")
                    or shutil.which("terratin") or "terratin")
    ap.add_argument("--plan", help="the plan (default OUT.gpkg.plan.json)")
    ap.add_argument("--keep", action="store_true",
                    help="keep the plan and the pieces after the merge")
    ap.add_argument("--overwrite", action="store_true")
    ap.add_argument("--stats", help="write per-tile figures as JSON here")
    ap.add_argument("dem")
    ap.add_argument("out")
    args, opts = ap.parse_known_args(argv)
    if args.workers < 1:
        ap.error("--workers must be 1 or more")
    try:
        import distributed
    except ImportError:
        print("tt_dask.py: %s has no Python package distributed "
              "(Debian: apt-get install python3-distributed, for "
              "/usr/bin/python3: run /usr/bin/python3 tt_dask.py ... when "
              "another python3 comes first on PATH)" % sys.executable,
              file=sys.stderr)
        return 3
    terratin = os.path.abspath(args.terratin) if os.sep in args.terratin \
        else args.terratin
    plan = os.path.abspath(args.plan or args.out + ".plan.json")
    ow = ["-overwrite"] if args.overwrite else []
    if os.path.exists(args.out) and not args.overwrite:
        print("tt_dask.py: %s: exists; use --overwrite to replace it"
              % args.out, file=sys.stderr)
        return 1
    t0 = time.monotonic()
    plan_opts, merge_opts = split_options(opts)
    r = subprocess.run([terratin, "tiles", "plan", args.dem, plan, "-q",
                        "-overwrite"] + plan_opts,
                       stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stderr)
        return r.returncode
    with open(plan) as f:
        ntiles = json.load(f)["tiles"]
    t_plan = time.monotonic() - t0

    cluster = None
    try:
        if args.scheduler:
            client = distributed.Client(args.scheduler)
        else:
            # Every listening socket on 127.0.0.1: the scheduler's and the
            # workers' HTTP servers are started even without a dashboard
            # (dashboard_address=None still binds :8787 on every interface
            # in distributed 2022.12), so they get 127.0.0.1 and a free port.
            cluster = distributed.LocalCluster(
                n_workers=args.workers, threads_per_worker=1,
                processes=True, host="127.0.0.1",
                dashboard_address="127.0.0.1:0",
                worker_dashboard_address="127.0.0.1:0")
            client = distributed.Client(cluster)
        nworkers = len(client.scheduler_info()["workers"])
        t1 = time.monotonic()
        futures = client.map(run_tile, [terratin] * ntiles, [plan] * ntiles,
                             range(ntiles), pure=False)
        tiles = []
        try:
            for fut in distributed.as_completed(futures):
                tiles.append(fut.result())
        except Exception as e:  # the first failure: the others are cancelled
            client.cancel(futures)
            print("tt_dask.py: %s; nothing written" % e, file=sys.stderr)
            return 1
        t_tiles = time.monotonic() - t1
        client.close()
    finally:
        if cluster is not None:
            cluster.close()

    t2 = time.monotonic()
    r = subprocess.run([terratin, "tiles", "merge", plan, args.out, "-q"]
                       + ow + merge_opts, stderr=subprocess.PIPE, text=True)
    t_merge = time.monotonic() - t2
    if r.returncode != 0:
        sys.stderr.write(r.stderr)
        return r.returncode
    if not args.keep:
        shutil.rmtree(plan + ".tiles", ignore_errors=True)
        os.unlink(plan)
    tiles.sort(key=lambda t: t["tile"])
    stats = {"tiles": ntiles, "workers": nworkers, "seconds_plan": t_plan,
             "seconds_tiles": t_tiles, "seconds_merge": t_merge,
             "seconds_total": time.monotonic() - t0, "per_tile": tiles}
    if args.stats:
        with open(args.stats, "w") as f:
            json.dump(stats, f, indent=1)
    print("%s: %d tiles on %d workers: %.2f s tiles, %.2f s merge, %.2f s "
          "in all" % (args.out, ntiles, nworkers, t_tiles, t_merge,
                      stats["seconds_total"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
