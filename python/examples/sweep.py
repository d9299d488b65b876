"""A sweep on Ray: scenes × techniques × shadow resolutions × sun elevations, each
case rendered by Gnomon and measured against its ray-traced reference, spread over
Ray workers (one renderer per worker, kept for all its cases). Writes a tidy table,
DIR/results.csv (one row per case, with error and cost), and DIR/pareto.png, the
error against the cost with each scene's Pareto front.

    python sweep.py --scenes spheres,contact,columns --techniques hard,pcf2x2,pcss \\
        --shadow-res 1024,2048 --sun-elevations 30,60 --out sweep

Locally, Ray uses this machine's cores. On a Ray cluster, give its address
(`--address ray://head:10001`, or `auto` on a node of it); every node needs
`pip install gnomon` (docs/python.md).
"""

import argparse
import csv
import os
import pathlib
import statistics
import time

import ray

import gnomon

# The columns of results.csv, in order.
COLUMNS = [
    "scene", "technique", "shadow_res", "sun_elevation", "width", "height",
    "mismatch_rate", "false_shadow_rate", "false_lit_rate", "mae",
    "frame_ms", "shadow_ms", "lighting_ms", "trace_ms", "adapter",
]


def listed(kind):
    def parse(text):
        items = [kind(item.strip()) for item in text.split(",") if item.strip()]
        if not items:
            raise argparse.ArgumentTypeError("give at least one value, comma-separated")
        return items
    return parse


@ray.remote
class Worker:
    """One renderer, kept for every case this worker runs."""

    def __init__(self):
        self.renderer = gnomon.Renderer()
        self.scenes = {}

    def run(self, scene_name, elevation, techniques, resolutions, size, samples, timing_frames, extra):
        """Every technique and resolution for one scene and sun: the reference is
        traced once and each frame is measured against it."""
        scene = self.scenes.setdefault(scene_name, gnomon.Scene.builtin(scene_name))
        view = dict(sun_elevation=elevation, width=size[0], height=size[1], **extra)
        truth = gnomon.reference(scene, gnomon.Settings(**view), samples=samples)
        rows = []
        for technique in techniques:
            for resolution in resolutions:
                settings = gnomon.Settings(technique=technique, shadow_res=resolution, **view)
                frame = self.renderer.render(scene, settings)
                measured = gnomon.compare(frame, truth)["drawn"]
                # The first frame compiles pipelines; time the frames after it, every
                # shadow map drawn again (kept maps would cost nothing), as a moving
                # light would.
                timed = settings.replace(map_cache="off")
                times = [self.renderer.render(scene, timed).times for _ in range(timing_frames)]

                def median(key):
                    values = [t[key] for t in times if t[key] is not None]
                    return statistics.median(values) if values else None

                rows.append({
                    "scene": scene_name, "technique": technique, "shadow_res": resolution,
                    "sun_elevation": elevation, "width": size[0], "height": size[1],
                    "mismatch_rate": measured["mismatch_rate"],
                    "false_shadow_rate": measured["false_shadow_rate"],
                    "false_lit_rate": measured["false_lit_rate"],
                    "mae": measured["mae"],
                    "frame_ms": median("frame_ms"), "shadow_ms": median("shadow_ms"),
                    "lighting_ms": median("lighting_ms"), "trace_ms": median("trace_ms"),
                    "adapter": self.renderer.adapter["name"],
                })
        return rows


def pareto_front(points):
    """The points no other point beats in both cost and error, by cost."""
    front = []
    for cost, error in sorted(points):
        if not front or error < front[-1][1]:
            front.append((cost, error))
    return front


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(10, 5.5), dpi=120)
    techniques = sorted({r["technique"] for r in rows})
    scenes = sorted({r["scene"] for r in rows})
    markers = "osD^v<>pP*"
    colours = plt.get_cmap("tab10")
    for s, scene in enumerate(scenes):
        for t, technique in enumerate(techniques):
            mine = [r for r in rows if r["scene"] == scene and r["technique"] == technique and r["frame_ms"]]
            axes.scatter(
                [r["frame_ms"] for r in mine], [100 * r["mismatch_rate"] for r in mine],
                marker=markers[s % len(markers)], color=colours(t % 10),
                label=f"{scene} · {technique}", alpha=0.8,
            )
        front = pareto_front([(r["frame_ms"], 100 * r["mismatch_rate"]) for r in rows if r["scene"] == scene and r["frame_ms"]])
        axes.plot([c for c, _ in front], [e for _, e in front], color="0.5", linewidth=0.8, linestyle="--")
    axes.set_xlabel("GPU frame time (ms, median)")
    axes.set_ylabel("light-facing pixels wrong against ray-traced truth (%)")
    axes.set_title("Error against cost; dashed: each scene's Pareto front")
    axes.grid(True, alpha=0.3)
    axes.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    figure.tight_layout()
    figure.savefig(path)
    plt.close(figure)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenes", type=listed(str), default=["spheres"])
    parser.add_argument("--techniques", type=listed(str), default=["hard", "pcf2x2", "pcss"])
    parser.add_argument("--shadow-res", type=listed(int), default=[1024, 2048])
    parser.add_argument("--sun-elevations", type=listed(float), default=[30.0, 60.0])
    parser.add_argument("--size", type=listed(int), default=[640, 360], help="WIDTH,HEIGHT of each image")
    parser.add_argument("--samples", type=int, default=64, help="shadow rays per pixel under an area light")
    parser.add_argument("--timing-frames", type=int, default=3)
    parser.add_argument("--set", type=listed(str), default=[], metavar="FLAG=VALUE,...",
                        help="settings for every case, as flags without dashes: --set refine=off,pcf_kernel=5")
    parser.add_argument("--workers", type=int, default=None, help="renderers (Ray actors); default: one per CPU")
    parser.add_argument("--address", default=None, help="a Ray cluster's address; default: a local Ray")
    parser.add_argument("--out", type=pathlib.Path, required=True)
    args = parser.parse_args()
    if len(args.size) != 2:
        parser.error("--size is WIDTH,HEIGHT")
    extra = {}
    for item in args.set:
        name, sep, value = item.partition("=")
        if not sep:
            parser.error(f"--set {item}: give FLAG=VALUE")
        extra[name.strip().replace("-", "_")] = value.strip()
    # Every value is checked before anything starts: a typo costs nothing.
    for scene in args.scenes:
        gnomon.Scene.builtin(scene)
    for technique in args.techniques:
        for resolution in args.shadow_res:
            for elevation in args.sun_elevations:
                gnomon.Settings(technique=technique, shadow_res=resolution, sun_elevation=elevation,
                                width=args.size[0], height=args.size[1], **extra)

    # The workers render on whatever Vulkan driver this process would use.
    env = {k: v for k, v in os.environ.items() if k in ("WGPU_BACKEND", "WGPU_ADAPTER_NAME", "VK_ICD_FILENAMES")}
    runtime_env = {"env_vars": env} if env else None
    if args.address:
        ray.init(address=args.address, runtime_env=runtime_env)
    else:
        ray.init(num_cpus=args.workers, runtime_env=runtime_env, include_dashboard=False)
    workers_wanted = args.workers or int(ray.cluster_resources().get("CPU", 1))
    workers = [Worker.options(num_cpus=1).remote() for _ in range(workers_wanted)]
    groups = [(s, e) for s in args.scenes for e in args.sun_elevations]
    started = time.monotonic()
    pool = ray.util.ActorPool(workers)
    size = tuple(args.size)
    jobs = pool.map_unordered(
        lambda worker, group: worker.run.remote(group[0], group[1], args.techniques, args.shadow_res,
                                                size, args.samples, args.timing_frames, extra),
        groups,
    )
    rows = []
    for done, group_rows in enumerate(jobs, start=1):
        rows.extend(group_rows)
        print(f"sweep: {done}/{len(groups)} scene and sun groups done ({len(rows)} cases)", flush=True)
    wall = time.monotonic() - started
    rows.sort(key=lambda r: (r["scene"], r["sun_elevation"], r["technique"], r["shadow_res"]))

    args.out.mkdir(parents=True, exist_ok=True)
    staged = args.out / "results.csv.partial"
    with staged.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    staged.replace(args.out / "results.csv")
    plot(rows, args.out / "pareto.png")
    print(f"sweep: {len(rows)} cases on {len(workers)} workers in {wall:.1f} s; wrote {args.out / 'results.csv'} "
          f"and {args.out / 'pareto.png'}")
    ray.shutdown()


if __name__ == "__main__":
    main()
