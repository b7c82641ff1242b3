"""pelage: a fur toolkit. Hair roots, grooms and curves files from Python.

    import pelage
    groom = pelage.Groom.load("fur.toml")
    curves = groom.grow()            # every part, joined
    print(curves.points.shape)       # (n, 3) float32, a view of pelage's memory
    groom.write("fur.usdc")          # streamed, atomic

The classes wrap pelage's Rust values (docs/python.md): `Mesh`, `Curves`,
`Groom`, `GroomSession` (brushes, undo, incremental regrowth), and
`sample()` for hair roots. `pelage.ops` builds the operator
tables of a groom (`ops=[pelage.ops.clump(count=300)]`). Errors are
`pelage.PelageError`, with the file, line and setting in the message.
"""

from ._pelage import (
    Curves,
    Groom,
    GroomSession,
    Mesh,
    PelageError,
    Samples,
    __build_profile__,
    __version__,
    read_curves,
    sample,
    write_curves,
)
from . import ops

__all__ = [
    "Curves",
    "Groom",
    "GroomSession",
    "Mesh",
    "PelageError",
    "Samples",
    "__build_profile__",
    "__version__",
    "ops",
    "read_curves",
    "sample",
    "write_curves",
]
