"""Groom operators as Python values: each function returns the table a
groom file's `[[ops]]` entry holds (docs/groom-format.md), so

    pelage.Groom(..., ops=[pelage.ops.clump(count=300, rate=0.8),
                           pelage.ops.curl(radius=0.002, turns=3)])

is the groom file's

    [[ops]]
    clump = { count = 300, rate = 0.8 }
    [[ops]]
    curl = { radius = 0.002, turns = 3 }

Every map argument takes a number or a map string ("density.png:r",
"noise:frequency=8", "vertex:red"). Every operator takes `mask`, a map
that fades its effect (0: none, 1: all of it). Arguments left as None
take the groom file's default. pelage checks the values when the groom is built and names the
setting in its error (`ops[1].curl.turns`).
"""

from typing import Any, Dict, Optional, Sequence, Union

Map = Union[float, str]
Ramp = Union[float, str, Sequence[float]]


def _op(name: str, **settings: Any) -> Dict[str, Dict[str, Any]]:
    return {name: {k: v for k, v in settings.items() if v is not None}}


def noise(amplitude: Map, frequency: Optional[Map] = None, ramp: Optional[Ramp] = None,
          vectors: Optional[int] = None, seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Perlin displacement of every point, `amplitude` world units at most."""
    return _op("noise", amplitude=amplitude, frequency=frequency, ramp=ramp, vectors=vectors, seed=seed, mask=mask)


def frizz(amplitude: Map, frequency: Optional[Map] = None, fraction: Optional[Map] = None,
          ramp: Optional[Ramp] = None, seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Per-hair random high-frequency displacement on a `fraction` of hairs."""
    return _op("frizz", amplitude=amplitude, frequency=frequency, fraction=fraction, ramp=ramp, seed=seed, mask=mask)


def clump(count: int, density: Optional[Map] = None, rate: Optional[Map] = None,
          ramp: Optional[Ramp] = None, size: Optional[Map] = None,
          seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Pulls hairs toward `count` clump centre hairs (`rate` 0 to 1)."""
    return _op("clump", count=count, density=density, rate=rate, ramp=ramp, size=size, seed=seed, mask=mask)


def curl(radius: Map, turns: Map, ramp: Optional[Ramp] = None,
         seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """A helix of `radius` around each hair's path, `turns` times root to tip."""
    return _op("curl", radius=radius, turns=turns, ramp=ramp, seed=seed, mask=mask)


def cut(at: Map,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Cuts every hair at curve parameter `at` (0 to 1)."""
    return _op("cut", at=at, mask=mask)


def length(scale: Map, jitter: Optional[Map] = None,
           seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Scales hair length by `scale`, ± `jitter` (a fraction) per hair."""
    return _op("length", scale=scale, jitter=jitter, seed=seed, mask=mask)


def strands(count: int, tip_spread: Map, root_spread: Optional[Map] = None,
            twist: Optional[Map] = None, seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Each hair becomes a strand of `count` hairs."""
    return _op("strands", count=count, root_spread=root_spread, tip_spread=tip_spread, twist=twist, seed=seed, mask=mask)


def width(root: Map, tip: Map, ramp: Optional[Ramp] = None, jitter: Optional[Map] = None,
          seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Widths (diameters) from `root` to `tip`."""
    return _op("width", root=root, tip=tip, ramp=ramp, jitter=jitter, seed=seed, mask=mask)


def color(root: Sequence[Map], tip: Sequence[Map], ramp: Optional[Ramp] = None,
          jitter: Optional[Map] = None, seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Colours (three maps each, linear RGB) from `root` to `tip`."""
    return _op("color", root=list(root), tip=list(tip), ramp=ramp, jitter=jitter, seed=seed, mask=mask)


def opacity(root: Map, tip: Map, ramp: Optional[Ramp] = None, jitter: Optional[Map] = None,
            seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Opacities from `root` to `tip`."""
    return _op("opacity", root=root, tip=tip, ramp=ramp, jitter=jitter, seed=seed, mask=mask)


def twist(angle: Map, ramp: Optional[Ramp] = None, jitter: Optional[Map] = None,
          seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """Turns each hair about its root–tip axis, `angle` degrees at the tip."""
    return _op("twist", angle=angle, ramp=ramp, jitter=jitter, seed=seed, mask=mask)


def flyaways(spread: Map, fraction: Optional[Map] = None, length: Optional[Map] = None,
             frequency: Optional[Map] = None, ramp: Optional[Ramp] = None,
             seed: Optional[int] = None,
        mask: Optional[Map] = None) -> Dict[str, Dict[str, Any]]:
    """A `fraction` of the hairs lengthened and pushed `spread` off their clump, each its own way."""
    return _op("flyaways", spread=spread, fraction=fraction, length=length, frequency=frequency,
               ramp=ramp, seed=seed, mask=mask)
