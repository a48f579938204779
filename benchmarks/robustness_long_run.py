"""Long robustness run (issue 7, section 1): the whole-pipeline property on many examples.

Runs the property of ``tests/trajopt/planning/test_plan_properties.py`` (random grids, robots and
queries; ``trajopt.plan`` must return a trajectory that holds every guarantee or raise a
documented error) without stopping at the first broken guarantee, then prints the outcome
counts per group (``easy``: open grids with well-placed end points) and every violation
with the parameters that reproduce it::

    python benchmarks/robustness_long_run.py              # 10 000 examples (~1 h on 2 cores)
    python benchmarks/robustness_long_run.py --examples 500

``pytest -m slow tests/trajopt/planning/test_plan_properties.py`` runs the same 10 000 examples as
a test (stopping and shrinking at the first failure). Exit code 1 when a guarantee broke.
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.trajopt.planning.test_plan_properties import (  # noqa: E402
    EASY_FAILURE_LIMIT,
    N_EXAMPLES_SLOW,
    run_property,
    summary,
)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--examples",
        type=int,
        default=N_EXAMPLES_SLOW,
        help=f"number of examples (default {N_EXAMPLES_SLOW})",
    )
    args = parser.parse_args(argv)
    if args.examples < 1:
        parser.error(f"--examples must be >= 1, got {args.examples}")
    counts: Counter = Counter()
    violations: list = []
    run_property(args.examples, counts, keep_going=True, violations=violations)
    print(summary(counts))
    easy = sum(v for k, v in counts.items() if isinstance(k, tuple) and k[0] == "easy")
    easy_fail = easy - counts[("easy", "ok")]
    print(f"easy cases that raised: {easy_fail}/{easy} (limit {EASY_FAILURE_LIMIT:.0%})")
    print(f"violations: {len(violations)}")
    for params, message in violations:
        print(f"- {message[:300]}\n  reproduce: build_case({params!r})")
    return 1 if violations else 0


if __name__ == "__main__":
    sys.exit(main())
