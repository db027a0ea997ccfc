#!/usr/bin/env python3
"""Sample random sewing patterns from GarmentCode's design generator.

Writes OUT/rand_SEED_I_specification.json (and the sampled design beside it,
OUT/rand_SEED_I_design.yaml) for I = 0 .. COUNT-1, each on GarmentCode's
average body measurements (assets/bodies/mean_all.yaml), ready for
`drape garment-plan OUT --body scenes/garmentcode/mean_all.obj`.

It samples as GarmentCode's own pattern_sampler.py does: a random design
from assets/design_params/default.yaml, redrawn while GarmentCode's checks
reject it (known bad parameter combinations, a garment longer than the body,
self-intersecting panels). Pattern I is drawn with random.seed(SEED + I), so
one pattern is reproducible on its own: the same panels and stitches each
time, though GarmentCode, which keeps some of them in sets, may write them in
another order (so stitch numbers can differ from one run to the next).

Needs a checkout of GarmentCode (its assets/ are not in the pip package) and
a Python with its dependencies:

    python3 -m venv venv-gc && venv-gc/bin/pip install pygarment
    venv-gc/bin/python scripts/sample-garmentcode.py GARMENTCODE_DIR OUT --count 10 --seed 1
"""

import argparse
import random
import sys
from pathlib import Path

import yaml


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("garmentcode", type=Path, help="GarmentCode checkout")
    p.add_argument("out", type=Path, help="folder to write the patterns into")
    p.add_argument("--count", type=int, default=10, help="patterns to write")
    p.add_argument("--seed", type=int, default=1, help="seed of the first pattern")
    p.add_argument("--tries", type=int, default=100, help="draws per pattern")
    return p.parse_args()


def sample_one(gc, body, sampler, name, tries):
    """Draws designs until GarmentCode accepts one; returns (design, pattern)."""
    for _ in range(tries):
        design = sampler.randomize()
        try:
            gc["assert_param_combinations"](design)
            piece = gc["MetaGarment"](name, body, design)
            piece.assert_total_length()
            if piece.is_self_intersecting():
                continue
            return design, piece.assembly()
        except KeyboardInterrupt:
            raise
        except BaseException as e:  # GarmentCode rejects a design by raising
            print(f"{name}: redrawn: {e}", file=sys.stderr)
    raise RuntimeError(f"{name}: no acceptable design in {tries} draws")


def main():
    args = parse_args()
    root = args.garmentcode.resolve()
    sys.path.insert(0, str(root))
    from assets.bodies.body_params import BodyParameters
    from assets.garment_programs.meta_garment import MetaGarment
    from pattern_sampler import assert_param_combinations
    import pygarment as pyg

    gc = {"MetaGarment": MetaGarment, "assert_param_combinations": assert_param_combinations}
    body = BodyParameters(root / "assets/bodies/mean_all.yaml")
    sampler = pyg.DesignSampler(root / "assets/design_params/default.yaml")
    args.out.mkdir(parents=True, exist_ok=True)
    for i in range(args.count):
        name = f"rand_{args.seed}_{i}"
        random.seed(args.seed + i)
        design, pattern = sample_one(gc, body, sampler, name, args.tries)
        pattern.serialize(args.out, to_subfolder=False)
        with open(args.out / f"{name}_design.yaml", "w") as f:
            yaml.dump({"design": design}, f, default_flow_style=False, sort_keys=False)
        meta = design["meta"]
        kinds = ", ".join(f"{k}={meta[k]['v']}" for k in ("upper", "bottom", "wb"))
        print(f"{name}: {len(pattern.pattern['panels'])} panels, {kinds}")


if __name__ == "__main__":
    main()
