"""The sweep example on a 2-worker local Ray, with a small grid."""

import csv
import os
import pathlib
import subprocess
import sys

SWEEP = pathlib.Path(__file__).resolve().parents[1] / "examples" / "sweep.py"


def test_a_small_sweep_on_two_ray_workers_writes_its_table_and_plot(tmp_path):
    argv = [
        sys.executable, str(SWEEP), "--scenes", "spheres,contact", "--techniques", "hard,pcf2x2",
        "--shadow-res", "256", "--sun-elevations", "35", "--size", "96,54", "--samples", "4",
        "--timing-frames", "1", "--set", "refine=off", "--workers", "2", "--out", str(tmp_path),
    ]
    done = subprocess.run(argv, capture_output=True, text=True, env={**os.environ, "RAY_AUTH_MODE": "disabled"})
    assert done.returncode == 0, done.stderr[-4000:]
    assert "4 cases on 2 workers" in done.stdout, done.stdout
    with (tmp_path / "results.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert sorted((r["scene"], r["technique"]) for r in rows) == [
        ("contact", "hard"), ("contact", "pcf2x2"), ("spheres", "hard"), ("spheres", "pcf2x2"),
    ]
    for row in rows:
        assert 0.0 <= float(row["mismatch_rate"]) <= 1.0
        assert float(row["frame_ms"]) > 0
        # Maps drawn again for timing: the shadow pass costs something.
        assert float(row["shadow_ms"]) > 0
    # 256² maps with no rays are wrong somewhere on these views.
    assert any(float(r["mismatch_rate"]) > 0 for r in rows)
    plot = (tmp_path / "pareto.png").read_bytes()
    assert plot[:8] == b"\x89PNG\r\n\x1a\n" and len(plot) > 10_000
