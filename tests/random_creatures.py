"""Random creature files: bilaterally symmetric walkers of 4-8 legs and 2-4 segments, 4 cm to 0.8 m across,
for checking the planner on creatures no session has seen (``footfall evaluate --creatures a.toml,b.toml``).

``python tests/random_creatures.py SEED N OUT_DIR`` writes ``rc0.toml`` ... ``rc{N-1}.toml``; the same seed
writes the same files. Each is valid (``footfall check``): every rest foot 0.65-0.86 of its leg's length from its hip.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np


def creature_text(rng: np.random.Generator, name: str) -> str:
    """One creature file's text, drawn from ``rng``."""
    size = float(np.exp(rng.uniform(np.log(0.04), np.log(0.8))))  # about its rest radius (m)
    per_side = int(rng.integers(2, 5))
    height = size * rng.uniform(0.2, 0.9)
    body_l, body_w = size * rng.uniform(0.4, 1.2), size * rng.uniform(0.3, 0.7)
    n_seg = int(rng.integers(2, 5))
    limits = [[-1.2, 0.8]] + [[-1.2, 1.4]] * (n_seg - 2) + [[0.0, 2.4]]
    lines = [f'name = "{name}"', 'description = "A random creature (tests/random_creatures.py)."',
             f"standing_height = {height:.4f}", f"body_thickness = {0.5 * height:.4f}",
             f"body_box = [{body_l:.4f}, {body_w:.4f}]",
             f"foot = {{ length = {0.08 * size:.4f}, width = {0.06 * size:.4f} }}", "",
             "[leg_defaults]", f"joint_limits = {limits}", ""]
    for i in range(per_side):
        t = (i + 0.5) / per_side
        forward = (0.5 - t) * body_l * 0.9
        lateral = body_w * 0.45
        angle = (0.5 - t) * rng.uniform(0.8, 1.6)  # front legs reach forward, hind legs back
        out = size * rng.uniform(0.6, 1.0)
        rest = (forward + out * math.sin(angle), lateral + out * math.cos(angle))
        reach = math.sqrt((rest[0] - forward) ** 2 + (rest[1] - lateral) ** 2 + height ** 2)
        weights = rng.uniform(0.5, 1.5, n_seg)
        segments = reach / 0.98 * rng.uniform(1.15, 1.5) * weights / weights.sum()
        seg_text = ", ".join(f"{s:.4f}" for s in segments)
        for side, sign in (("L", 1.0), ("R", -1.0)):  # the right leg mirrors the left
            lines += ["[[legs]]", f'name = "{side}{i + 1}"', f"hip = [{forward:.4f}, 0.0, {sign * lateral:.4f}]",
                      f"rest_foot = [{rest[0]:.4f}, {sign * rest[1]:.4f}]", f"segments = [{seg_text}]", ""]
    return "\n".join(lines)


def write_creatures(seed: int, n: int, out_dir) -> list[Path]:
    rng = np.random.default_rng(seed)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for k in range(n):
        path = out / f"rc{k}.toml"
        path.write_text(creature_text(rng, f"rc{k}") + "\n")
        paths.append(path)
    return paths


if __name__ == "__main__":
    seed, n, out_dir = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    for p in write_creatures(seed, n, out_dir):
        print(p)
