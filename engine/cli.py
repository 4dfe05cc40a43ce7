"""The ``colldet`` command: the chapter's algorithms from a shell, each on what the installed package holds.

    colldet fall --height 10 --restitution 0.8 [--drag 0.2] [--cube]
    colldet sap-example
    colldet contact A.json B.json
    colldet bound POINTS.csv | colldet hull POINTS.csv | colldet decompose POLYGON.csv
    colldet gas --n 2000 --eta 0.2 --method events
    colldet demo [--png demo.png] [--no-gif]
    colldet warmup [--jobs N]       (compile every kernel once, e.g. after installing)
    colldet --version               (also: python -m engine ...)

Every file argument is checked before the work starts; an error is one line on stderr and a non-zero exit
status (2 for bad arguments, 1 for a file that cannot be written). Results are printed before files are written.
(The benchmark and validation reports are generated from a source checkout: ``python -m bench.report``.)
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

PROG = "colldet"


def _float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    return value


def _jobs(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def readable_file(path: str, name: str) -> Path:
    """``path`` as a Path when it names a readable regular file; else ValueError naming ``name``."""
    p = Path(path)
    if p.is_dir():
        raise ValueError(f"{name}: {path} is a directory, not a file")
    if not p.is_file():
        raise ValueError(f"{name}: no such file: {path}")
    if not os.access(p, os.R_OK):
        raise ValueError(f"{name}: {path} is not readable")
    return p


def writable_file(path: str, name: str) -> Path:
    """``path`` as a Path when a file can be written there (its folder exists and is writable, and it is not a
    directory); else ValueError naming ``name``. Nothing is created."""
    p = Path(path)
    folder = p.parent if str(p.parent) else Path(".")
    if p.is_dir():
        raise ValueError(f"{name}: {path} is a directory; give a file name")
    if not folder.is_dir():
        raise ValueError(f"{name}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
        raise ValueError(f"{name}: {path} is not writable")
    return p


def writable_folder(path: str, name: str) -> Path:
    """``path`` as a Path when it is (or can be created as) a writable folder; else ValueError naming ``name``."""
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise ValueError(f"{name}: {path} exists and is not a folder")
    existing = p
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir() or not os.access(existing, os.W_OK):
        raise ValueError(f"{name}: cannot create or write into {path}")
    return p


def _write_csv(path: Path, columns: dict) -> None:
    """One column per key, full float64 precision (no pandas needed)."""
    import numpy as np

    data = np.column_stack([np.asarray(v, dtype=float) for v in columns.values()])
    np.savetxt(path, data, delimiter=",", header=",".join(columns), comments="", fmt="%.17g")


def _fall_table(args):
    """Run the fall and return ``(label, result, rows)``: rows are (t_c, v_before, v_after)."""
    from .dynamics.scenes import drop_cube, drop_particle

    if args.cube:
        res = drop_cube(args.height, size=args.size, mass=args.mass, drag=args.drag, gravity=args.gravity,
                        dt=args.dt, tol=args.tol, t_end=args.t_end, quadratic_drag=args.quadratic_drag)
        rows = [] if res.t_contact is None else [(res.t_contact, res.v_contact, 0.0)]
        return "cube (centre)", res, rows
    res = drop_particle(args.height, mass=args.mass, drag=args.drag, restitution=args.restitution,
                        gravity=args.gravity, dt=args.dt, t_end=args.t_end, tol=args.tol,
                        quadratic_drag=args.quadratic_drag)
    return "particle", res, [(imp.t, imp.v_before, imp.v_after) for imp in res.impacts]


def cmd_fall(args) -> int:
    """Drop a particle (or the cube), print the impacts, write a PNG plot of y(t) and a CSV trajectory."""
    import numpy as np

    from .dynamics.plot import plot_fall

    out = writable_folder(args.out, "--out")
    label, res, rows = _fall_table(args)
    print(f"{label} dropped from y = {args.height} (dt = {args.dt}, tol = {args.tol}, e = "
          f"{0.0 if args.cube else args.restitution}, drag = {args.drag})")
    print(f"{'#':>3}  {'t_c (s)':>14}  {'v_before (m/s)':>15}  {'v_after (m/s)':>14}")
    for k, (tc, vb, va) in enumerate(rows, 1):
        print(f"{k:>3}  {tc:14.10f}  {vb:15.10f}  {va:14.10f}")
    if not rows:
        print("  (no impact before t_end)")
    if args.cube and res.t_contact is not None:
        print(f"cube stopped at t = {res.t_contact:.10f} s, centre {res.position.tolist()}, velocity "
              f"{res.velocity.tolist()}")
    elif not args.cube and res.rest_time is not None:
        print(f"resting contact from t = {res.rest_time:.10f} s (contact force m g = {args.mass * args.gravity:g} N)")
    stem = "fall_cube" if args.cube else "fall_particle"
    out.mkdir(parents=True, exist_ok=True)
    _write_csv(out / f"{stem}.csv", {"t": res.t, "y": res.y, "v": res.v})
    t_hits = [r[0] for r in rows]
    plot_fall(res.t, res.y, t_hits, np.interp(t_hits, res.t, res.y), label, path=out / f"{stem}.png")
    print(f"wrote {out / (stem + '.csv')} and {out / (stem + '.png')}")
    return 0


def cmd_sap_example(args) -> int:
    """The slide's 1-D sweep-and-prune example, step by step (event, active list, pairs reported)."""
    from .broadphase import sap_example_trace

    print(sap_example_trace())
    return 0


def cmd_contact(args) -> int:
    """Whether, where (point, normal, feature) and when two shapes given as JSON files collide."""
    from .contact_io import describe_contact

    a = readable_file(args.shape_a, "shape_a")
    b = readable_file(args.shape_b, "shape_b")
    print(describe_contact(str(a), str(b), t_max=args.t_max))
    return 0


def cmd_gas(args) -> int:
    """The confined ideal gas: Z, Γ, energy drift, collisions per second, the speed histogram (PNG)."""
    from .gas.command import run_gas_command

    writable_file(args.out, "--out")
    return run_gas_command(n=args.n, eta=args.eta, method=args.method, boundary=args.boundary,
                           t_measure=args.t_measure, seed=args.seed, out=args.out, progress=not args.no_progress,
                           dt=args.dt, broad_phase=args.broad_phase, t_equilibrate=args.t_equilibrate)


def cmd_demo(args) -> int:
    """Boxes, spheres and capsules falling with RK4 onto a curved ground: an animated GIF and/or a still PNG."""
    from .demo_plot import run_demo

    if not args.no_gif:
        writable_file(args.out, "--out")
    if args.png is not None:
        writable_file(args.png, "--png")
    return run_demo(out=None if args.no_gif else args.out, png=args.png, frames=args.frames,
                    png_frame=args.png_frame, restitution=args.restitution, seed=args.seed)


def _read_points(path: str, name: str):
    import numpy as np

    readable_file(path, name)
    try:
        return np.loadtxt(path, delimiter=",", ndmin=2)
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path}: cannot read a CSV of points, one point per line ({exc})") from None


def cmd_bound(args) -> int:
    """Fit bounding volumes to a CSV of points and print them (JSON)."""
    import json

    from .bounding import describe_bounding_volumes

    kinds = args.kinds.split(",") if args.kinds else None
    print(json.dumps(describe_bounding_volumes(_read_points(args.points, "points"), kinds=kinds), indent=2))
    return 0


def cmd_hull(args) -> int:
    """The convex hull of a CSV of points (JSON)."""
    import json

    from .bounding import describe_hull

    print(json.dumps(describe_hull(_read_points(args.points, "points")), indent=2))
    return 0


def cmd_decompose(args) -> int:
    """A simple polygon (CSV, one vertex per line, boundary order) split into convex pieces (JSON)."""
    import json

    from .bounding import describe_decomposition

    print(json.dumps(describe_decomposition(_read_points(args.polygon, "polygon")), indent=2))
    return 0


def cmd_warmup(args) -> int:
    """Compile (or load from the cache) every kernel of the engine, with a progress bar."""
    from .warmup import warm_up

    seconds = warm_up(progress=not args.no_progress, jobs=args.jobs)
    print(f"every kernel is compiled and cached ({seconds:.1f} s)")
    return 0


def _add_fall(sub) -> None:
    fall = sub.add_parser("fall", help="drop a particle (or a cube) on the ground: impacts, plot, CSV",
                          description="RK4 with drag, impact times by bisection (Algorithme 3), "
                                      "v_after = -e v_before, resting contact.")
    fall.add_argument("--height", type=_float, default=10.0, help="initial height in m (default 10)")
    fall.add_argument("--restitution", "-e", type=_float, default=1.0, help="e in [0, 1] (default 1)")
    fall.add_argument("--drag", type=_float, default=0.0, help="linear drag k in F = -k v (default 0)")
    fall.add_argument("--quadratic-drag", type=_float, default=0.0, help="c in F = -c |v| v (default 0)")
    fall.add_argument("--mass", type=_float, default=1.0, help="mass in kg (default 1)")
    fall.add_argument("--gravity", type=_float, default=9.81, help="g in m/s^2 (default 9.81)")
    fall.add_argument("--dt", type=_float, default=0.01, help="RK4 step in s (default 0.01)")
    fall.add_argument("--tol", type=_float, default=1e-10, help="bisection tolerance on tc in s")
    fall.add_argument("--t-end", type=_float, default=10.0, help="simulated time in s (default 10)")
    fall.add_argument("--cube", action="store_true", help="drop the slide's cube instead (stopped at contact)")
    fall.add_argument("--size", type=_float, default=1.0, help="cube edge in m (default 1)")
    fall.add_argument("--out", default=".", help="folder for fall_*.png and fall_*.csv (default .)")
    fall.set_defaults(func=cmd_fall)


def _add_shapes(sub) -> None:
    """sap-example, bound, hull, decompose, contact: the commands on shapes given in files."""
    from .bounding import BOUNDING_KINDS

    sap = sub.add_parser("sap-example", help="the slide's 1-D sweep-and-prune example, step by step",
                         description="Sorted list of all b_i and e_i, swept with a list of active intervals "
                                     "(slide \"Algorithmes de balayage et de tri\").")
    sap.set_defaults(func=cmd_sap_example)
    bound = sub.add_parser("bound", help="fit bounding volumes (sphere, AABB, OBB, k-DOPs) to a CSV of points",
                           description="Each volume with its parameters and its measure (area or volume).")
    bound.add_argument("points", help="CSV file, one point (x,y[,z]) per line")
    bound.add_argument("--kinds", help=f"comma-separated subset of {','.join(BOUNDING_KINDS)}")
    bound.set_defaults(func=cmd_bound)
    hull = sub.add_parser("hull", help="the convex hull of a CSV of points (quickhull / monotone chain)")
    hull.add_argument("points", help="CSV file, one point (x,y[,z]) per line")
    hull.set_defaults(func=cmd_hull)
    decompose = sub.add_parser("decompose", help="split a simple polygon (CSV) into convex pieces",
                               description="Ear-clipping triangulation, then Hertel-Mehlhorn.")
    decompose.add_argument("polygon", help="CSV file, one vertex (x,y) per line, in boundary order")
    decompose.set_defaults(func=cmd_decompose)
    contact = sub.add_parser("contact", help="whether, where and when two shapes (JSON files) collide",
                             description="Shapes, poses and velocities in the JSON format documented in "
                                         "engine/contact_io.py.")
    contact.add_argument("shape_a", help="JSON file of shape A")
    contact.add_argument("shape_b", help="JSON file of shape B")
    contact.add_argument("--t-max", type=_float, default=10.0, help="look for an impact up to this time (s)")
    contact.set_defaults(func=cmd_contact)


def _add_gas(sub) -> None:
    from .broadphase import BROAD_PHASES

    gas = sub.add_parser("gas", help="the confined ideal gas: Z, collision rate, energy drift, speed histogram",
                         description="Elastic spheres in the chapter's box of side 10 (walls at +-5).")
    gas.add_argument("--n", type=int, default=2000, help="number of spheres (default 2000)")
    gas.add_argument("--eta", type=_float, default=0.2, help="packing fraction (default 0.2)")
    gas.add_argument("--method", choices=["events", "stepped"], default="events", help="default events")
    gas.add_argument("--boundary", choices=["walls", "periodic"], default="walls", help="default walls")
    gas.add_argument("--broad-phase", choices=list(BROAD_PHASES), default="sap",
                     help="broad phase of the stepped method (default sap)")
    gas.add_argument("--dt", type=_float, default=1e-3, help="time step of the stepped method (default 1e-3)")
    gas.add_argument("--t-equilibrate", type=_float, default=5.0, help="equilibration time (default 5)")
    gas.add_argument("--t-measure", type=_float, default=20.0, help="measurement time (default 20)")
    gas.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    gas.add_argument("--out", default="gas_speeds.png", help="speed histogram PNG (default gas_speeds.png)")
    gas.add_argument("--no-progress", action="store_true", help="no progress bar")
    gas.set_defaults(func=cmd_gas)


def _add_demo(sub) -> None:
    demo = sub.add_parser("demo", help="bodies falling on a curved ground through the World pipeline (GIF/PNG)",
                          description="RK4 + bisection impacts; bodies, contact points, normals, per-stage counts.")
    demo.add_argument("--out", default="demo.gif", help="animated GIF (default demo.gif)")
    demo.add_argument("--no-gif", action="store_true", help="write only the still frame (needs --png)")
    demo.add_argument("--png", default=None, help="also write one still frame to this PNG")
    demo.add_argument("--frames", type=int, default=150, help="number of frames of 0.02 s (default 150)")
    demo.add_argument("--png-frame", type=int, default=70, help="frame written by --png (default 70)")
    demo.add_argument("--restitution", type=_float, default=0.6, help="restitution on the ground (default 0.6)")
    demo.add_argument("--seed", type=int, default=0, help="random seed of the hull's points (default 0)")
    demo.set_defaults(func=cmd_demo)


def _add_warmup(sub) -> None:
    warmup = sub.add_parser("warmup", help="compile every kernel once (after installing, or in an image build)",
                            description="The first call of each compiled kernel compiles it (about a minute in "
                                        "all); the machine code is then cached on disk. This runs every kernel "
                                        "once on small inputs so that later calls start at once.")
    warmup.add_argument("--no-progress", action="store_true", help="no progress bar")
    warmup.add_argument("--jobs", type=_jobs, default=os.cpu_count() or 1, metavar="N",
                        help="processes compiling at once, each a share of the kernels of about equal cost "
                             "(default: one per CPU core)")
    warmup.set_defaults(func=cmd_warmup)


def version() -> str:
    """The installed distribution's version (from its metadata), else the package's own."""
    from . import __version__

    return __version__


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description="Collision detection for game physics: whether, where and when two objects collide.")
    parser.add_argument("--version", action="version", version=f"{PROG} {version()}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for add in (_add_fall, _add_shapes, _add_gas, _add_demo, _add_warmup):
        add(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (ValueError, TypeError) as exc:
        print(f"{PROG} {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"{PROG} {args.command}: error: {exc.strerror or exc}: {exc.filename or ''}".rstrip(": "),
              file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
