"""``benchmarks/bench_inverse.py --fit linear`` (``eroad invert --fit linear``), under the
name the linear-fit result folders were made with.

Run:  nice python benchmarks/bench_inverse_linear.py --scenario null --cases 10 --root R1 --data-root D
      (every option is bench_inverse.py's)
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main(argv=None) -> int:
    import bench_inverse

    return bench_inverse.main(["--fit", "linear"] + list(sys.argv[1:] if argv is None else argv))


if __name__ == "__main__":
    sys.exit(main())
