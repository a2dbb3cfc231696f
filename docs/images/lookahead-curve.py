"""Plots beat lift and speech coupling against the look-ahead (docs/images/lookahead-curve.png).

Usage: python3 lookahead-curve.py OUT.png NAME=EVAL.json ...
where each EVAL.json is `gesture-train eval-motion --json --lookahead-ms 0,100,300,500,1000,all`
output; the capture's level (its `mocap` row), when there is one, is drawn as a dashed line.
Needs matplotlib.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

XS = [0, 100, 300, 500, 1000]
ALL_X = 1300


def rows(path):
    d = json.load(open(path))
    return {r["method"]: r for r in d["rows"]}


def main():
    out, specs = sys.argv[1], sys.argv[2:]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for k, (field, title) in enumerate(
        [("beat_lift", "beat lift (strokes on syllables)"), ("speech_coupling", "speech coupling")]
    ):
        ax = axes[k]
        for i, spec in enumerate(specs):
            name, path = spec.split("=", 1)
            r = rows(path)
            xs = [x for x in XS if f"lookahead_{x}" in r]
            ys = [r[f"lookahead_{x}"][field] for x in xs]
            if "lookahead_all" in r:
                xs.append(ALL_X)
                ys.append(r["lookahead_all"][field])
            color = f"C{i}"
            ax.plot(xs, ys, "o-", color=color, label=name)
            if "mocap" in r:
                ax.axhline(r["mocap"][field], color=color, linestyle="--", linewidth=1)
        ax.set_xticks(XS + [ALL_X])
        ax.set_xticklabels([str(x) for x in XS] + ["all"])
        ax.set_xlabel("look-ahead (ms)")
        ax.set_title(title)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(
        "Known audio: 30-run means (all: 30 plans); dashed, the capture of the same speech",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
