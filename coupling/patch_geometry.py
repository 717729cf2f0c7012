"""The moving soil patch's lengths (:class:`PatchGeometry`): what a periodic bin must hold around the wheel, checked
before any bed exists, with no Taichi (:mod:`.patch` moves the soil and explains the scheme)."""

from __future__ import annotations

from dataclasses import dataclass

from wheelsoil.errors import WheelsoilInputError


@dataclass(frozen=True)
class PatchGeometry:
    """The lengths [m] that keep a moving patch's ends and renewed zone clear of the wheel (see the module
    docstring): bin ``length``, the wheel's outer radius ``reach``, ``shift``, the clearances ``ahead`` and
    ``behind``, the ``buffer`` re-placed with each renewal. Checked before any bed is prepared."""

    length: float
    reach: float
    shift: float
    ahead: float
    behind: float
    buffer: float

    @classmethod
    def for_wheel(cls, length: float, reach: float, shift: float, diameter_max: float) -> "PatchGeometry":
        """The defaults: 0.4 and 0.25 of the wheel's reach clear ahead and behind, three of the largest particle
        diameters of buffer."""
        if not shift > 0:
            raise WheelsoilInputError(f"patch shift = {shift!r} m must be > 0")
        return cls(float(length), float(reach), float(shift), 0.4 * reach, 0.25 * reach, 3.0 * diameter_max)

    def required_length(self) -> float:
        """Shortest bin [m] that keeps both ends and the renewed zone clear of the wheel."""
        return 2.0 * self.reach + self.ahead + self.behind + 2.0 * self.shift + self.buffer

    def start_range(self) -> tuple[float, float]:
        """Where the wheel's hub may start [m]: the renewed zone and the rear end stay clear of it."""
        return self.reach + self.behind, self.length - 2.0 * self.shift - self.buffer - self.reach - self.ahead

    def check(self, start_x: float | None) -> float:
        """The start position (default: as near the rear as allowed), or an error naming keys and values."""
        need = self.required_length()
        if self.length < need - 1e-12:
            raise WheelsoilInputError(
                f"the periodic bin (soil.length = {self.length:g} m) is too short for a moving patch around a wheel "
                f"of outer radius {self.reach:.3f} m: it needs at least {need:.3f} m (2 x {self.reach:.3f} m of wheel, "
                f"{self.ahead:.3f} m clear ahead, {self.behind:.3f} m behind, 2 x {self.shift:.3f} m of patch shift "
                f"and a {self.buffer:.3f} m buffer)")
        lo, hi = self.start_range()
        x = lo if start_x is None else float(start_x)
        if not lo - 1e-12 <= x <= hi + 1e-12:
            raise WheelsoilInputError(
                f"test.start_x = {x:.3f} m puts the wheel too near the moving patch's ends: on this periodic bin it "
                f"must lie in [{lo:.3f}, {hi:.3f}] m")
        return x
