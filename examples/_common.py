"""What the examples share: command-line options and a headless matplotlib."""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # write PNG files; no display needed

import matplotlib.pyplot as plt  # noqa: E402


def options(name, doc):
    """--out FILE (default examples/out/NAME.png) and --quick (the short run the tests use)."""
    parser = argparse.ArgumentParser(description=doc)
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path(__file__).parent / "out" / f"{name}.png")
    parser.add_argument("--quick", action="store_true", help="a shorter run, as the tests do")
    args = parser.parse_args()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    return args


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")
