"""Hidden-effect campaign: draw N synthetic datasets, each with one mechanism (or none) hidden at a random
magnitude, run the discovery workflow on each, and count how often it names the hidden mechanism.

Usage (from the repository root; under a minute a draw on 2 cores with the nine candidates)::

    python docs/validation_campaign.py --seed 11 --draws 16
"""

import argparse
import sys
from collections import Counter

import numpy as np


def main(argv=None) -> int:
    from wheelsoil.validation.discovery import discover
    from wheelsoil.validation.synthetic import HIDDEN_RANGES, draw_hidden_effect, synthetic_measurements

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--draws", type=int, default=16)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    tally = Counter()
    for k in range(args.draws):
        hidden, params = draw_hidden_effect(rng, list(HIDDEN_RANGES) + [None])
        found = discover(synthetic_measurements(params, rng), seed=k).found
        name = found.extension.name if found else None
        tally["right" if name == hidden else "wrong"] += 1
        detail = (f"{found.extension.name} {found.fit.free} gain {found.gain:.3f} +- {found.gain_std:.3f}"
                  if found else "nothing")
        print(f"draw {k:2d}: hidden {hidden} {params} -> found {detail}", flush=True)
    print(f"named correctly: {tally['right']} of {args.draws}")
    return 0 if tally["wrong"] == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
