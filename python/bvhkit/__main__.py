"""python -m bvhkit COMMAND [arguments]

Commands:
  sample-sdf  signed-distance samples for a folder of meshes, optionally over Dask workers
              (bvhkit.sample_sdf; python -m bvhkit sample-sdf --help)
  bench       the benchmark workloads (bvhkit.bench; also python -m bvhkit.bench)
"""

from __future__ import annotations

import sys
from typing import Optional, Sequence


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Dispatches to the command's own main; returns the exit status."""
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if args else 2
    command, rest = args[0], args[1:]
    if command == "sample-sdf":
        from . import sample_sdf

        return sample_sdf.main(rest)
    if command == "bench":
        from . import bench

        bench.main(rest)
        return 0
    print(f"python -m bvhkit: unknown command {command!r}\n\n{__doc__.strip()}", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
