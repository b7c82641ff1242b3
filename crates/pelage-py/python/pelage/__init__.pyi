from . import ops as ops
from ._pelage import (
    Curves as Curves,
    Groom as Groom,
    GroomSession as GroomSession,
    Mesh as Mesh,
    PelageError as PelageError,
    Samples as Samples,
    __version__ as __version__,
    read_curves as read_curves,
    sample as sample,
    write_curves as write_curves,
)
