#!/usr/bin/env python3
"""Wall frame against GPU frame + CPU submit, per technique, from `gnomon bench`
reports: the median over frames of wall / (GPU frame + CPU submit), which is 1 when a
frame costs nothing beyond its GPU work and its submission (no resource creation, no
stall). With two report directories (before and after a change), prints both.

    python3 scripts/wall-overhead.py BENCH_DIR [BENCH_DIR_AFTER]
"""
import json, statistics, sys

def ratios(path):
    report = json.load(open(f"{path}/bench.json"))
    out = {}
    for config in report["configs"]:
        series = {p["name"]: p["values_ms"] for p in config["passes"]}
        wall, gpu, cpu = series["wall frame"], series["GPU frame"], series["CPU submit"]
        per_frame = [w / (g + c) for w, g, c in zip(wall, gpu, cpu)]
        out[config["technique"]] = (statistics.median(wall), statistics.median(gpu),
                                    statistics.median(cpu), statistics.median(per_frame))
    return report["scene"], out

def main(dirs):
    sides = [ratios(d) for d in dirs]
    scene = sides[0][0]
    head = "| technique |" + "".join(
        f" {name}: wall | GPU + CPU | wall ÷ (GPU + CPU) |" for name in (["before", "after"][:len(dirs)] if len(dirs) == 2 else [""]))
    print(f"**{scene}**\n")
    print(head)
    print("|---|" + "---|---|---|" * len(dirs))
    for technique in sides[0][1]:
        row = f"| {technique} |"
        for _, table in sides:
            wall, gpu, cpu, r = table[technique]
            row += f" {wall:.1f} | {gpu + cpu:.1f} | {r:.3f} |"
        print(row)
    print()

if __name__ == "__main__":
    main(sys.argv[1:])
