"""The Schulze sequence of the shear-cell deck as a timeline of ``run`` segments.

Phase 0: settle, scrape, compress with the servo lid to the pre-shear load. Then one cycle per
value of P: pre-shear at the full load (phase 1), unload the lid to ``unload_force_fraction`` of
that load with the lower part at rest (phase 2), shear at ``P`` times the pre-shear load
(phase 3). Several cycles follow each other in one of three ways (``shear_cell.cycles``):
"return" (every cycle starts at zero offset; in between the lower part returns with the lid
unloaded and the sample is compressed again), "alternate" (the direction alternates, the
offset swings between +h and -h) or "continue" (ring cell only: the next pre-shear follows the
shear in the same direction, as in a Schulze ring shear tester). Steps are counted from the
start of the run; offsets are the x displacement of the lower part against the upper ring
(the ring: travel along the mean circle), m.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from demcal.particles.run_setup import steps_for

__all__ = ["DeckSegment", "Schedule", "ShearCycle", "Timeline", "schulze_schedule"]


@dataclass(frozen=True)
class DeckSegment:
    """One ``run`` of the shear-cell deck with constant settings.

    Attributes
    ----------
    label : str
        What the segment does (written as a comment into the deck).
    phase, cycle : int
        Values of the print columns ``phase`` and ``cycle``.
    target_force : float
        Lid force the servo holds, N (positive).
    target_val : float
        The servo's ``target_val``, ``-target_force`` (the lid pushes towards -z), N.
    ctrl : tuple of float
        Servo gains (kp, ki, kd): the configured gains times ``target_force`` over the
        pre-shear force. LIGGGHTS divides the force error by the target, so this keeps the lid's
        response to a given force error the same in every segment (a tiny unload target would
        otherwise make the lid chatter at full speed).
    moving : bool
        Whether the lower part moves.
    velocity : float
        x velocity of the lower part, m/s (0 at rest).
    travel_per_step : float
        x displacement of the lower part per step, m.
    offset_start : float
        x offset of the lower part against the upper ring at the first step, m.
    start_step, steps : int
        First step and number of steps.
    snapshot : bool
        Write the particle snapshot (VTK) at the end of the segment.
    """

    label: str
    phase: int
    cycle: int
    target_force: float
    target_val: float
    ctrl: tuple[float, float, float]
    moving: bool
    velocity: float
    travel_per_step: float
    offset_start: float
    start_step: int
    steps: int
    snapshot: bool = False

    @property
    def end_step(self) -> int:
        """Last step of the segment."""
        return self.start_step + self.steps

    @property
    def offset_end(self) -> float:
        """x offset of the lower part at the last step, m."""
        return self.offset_start + self.steps * self.travel_per_step


@dataclass(frozen=True)
class ShearCycle:
    """One pre-shear / unload / shear cycle (the readout's view of the deck).

    Attributes
    ----------
    index : int
        Cycle number (0, 1, ...).
    P : float
        Shear load as a fraction of the pre-shear load, -.
    direction : int
        -1 (lower part moves towards -x) or +1.
    preshear_force, shear_force : float
        Servo target lid forces of pre-shear and shear, N.
    preshear_start_step, preshear_end_step, shear_start_step, shear_end_step : int
        First and last steps of the pre-shear and the shear phase.
    offset_preshear_start, offset_shear_end : float
        x offset of the lower part at the start of the pre-shear and at the end of the shear, m.
    """

    index: int
    P: float
    direction: int
    preshear_force: float
    shear_force: float
    preshear_start_step: int
    preshear_end_step: int
    shear_start_step: int
    shear_end_step: int
    offset_preshear_start: float
    offset_shear_end: float


class Timeline:
    """Appends deck segments one after the other, tracking step and offset.

    Parameters
    ----------
    start_step : int
        Step at which the first segment starts.
    force : float
        Pre-shear lid force, N (the servo gains are scaled by target force over this).
    gains : tuple of float
        Servo gains (kp, ki, kd) at ``force``.
    """

    def __init__(self, start_step: int, force: float, gains: tuple[float, float, float]):
        self.step = start_step
        self.offset = 0.0
        self.force = force
        self.gains = gains
        self.segments: list[DeckSegment] = []

    def add(
        self,
        label: str,
        phase: int,
        cycle: int,
        target: float,
        steps: int,
        velocity: float = 0.0,
        dt: float = 0.0,
        snapshot: bool = False,
    ) -> DeckSegment:
        """Append a segment of ``steps`` steps at lid force ``target`` (N) and lower-part
        velocity ``velocity`` (m/s, time step ``dt`` in s) and return it."""
        factor = target / self.force
        seg = DeckSegment(
            label=label,
            phase=phase,
            cycle=cycle,
            target_force=target,
            target_val=-target,
            ctrl=(self.gains[0] * factor, self.gains[1] * factor, self.gains[2] * factor),
            moving=velocity != 0.0,
            velocity=velocity,
            travel_per_step=velocity * dt,
            offset_start=self.offset,
            start_step=self.step,
            steps=steps,
            snapshot=snapshot,
        )
        self.segments.append(seg)
        self.step = seg.end_step
        self.offset = seg.offset_end
        return seg


@dataclass(frozen=True)
class Schedule:
    """The segments and cycles of one shear-cell deck.

    Attributes
    ----------
    segments : tuple of DeckSegment
        Every ``run`` after the filling, in order (phase 0 compression onwards).
    cycles : tuple of ShearCycle
        One per value of P, in order.
    end_step : int
        Last step of the run.
    """

    segments: tuple[DeckSegment, ...]
    cycles: tuple[ShearCycle, ...]
    end_step: int

    @property
    def max_offset(self) -> float:
        """Largest misalignment of the lower part against the upper ring, m."""
        return max(max(abs(s.offset_start), abs(s.offset_end)) for s in self.segments)


def schulze_schedule(
    *,
    mode: str,
    p_values: Sequence[float],
    force: float,
    gains: tuple[float, float, float],
    start_step: int,
    compress_steps: int,
    preshear_steps: int,
    unload_steps: int,
    run_in_steps: int = 0,
    shear_steps: int,
    speed: float,
    return_speed: float,
    unload_fraction: float,
    dt: float,
) -> Schedule:
    """The Schulze sequence after the filling: compression, then one cycle per value of P.

    Two ways of running several cycles:

    * ``"alternate"``: after the compression the lower part moves under load to ``+h``, half
      the travel of one cycle; cycle k then moves towards -x for even k and +x for odd k, so the
      offset swings between ``+h`` and ``-h``, every cycle starts after a reversal and sweeps
      the same, mirrored geometry.
    * ``"return"``: every cycle moves towards -x from zero offset; between cycles the lid is
      unloaded to ``unload_fraction`` of the pre-shear force, the lower part returns to zero
      offset at ``return_speed``, and the lid compresses the sample again (phase 0 of the next
      cycle). Every cycle then starts like a fresh test.
    * ``"continue"``: every cycle moves towards -x and the pre-shear of cycle k + 1 follows the
      shear of cycle k at once (the servo reloads the lid while the lower part turns on), as
      a Schulze ring shear tester runs its sequence. Only a ring can do this: its lower part
      turns in place, while the offset of a split cell would grow by one cycle's travel per
      cycle. No reversal, no return: later cycles meet the fabric the earlier ones built.

    Parameters
    ----------
    mode : {"alternate", "return", "continue"}
        How cycles follow each other.
    p_values : sequence of float
        Shear loads as fractions of the pre-shear load, one cycle each, -.
    force : float
        Pre-shear lid force, N.
    gains : tuple of float
        Servo gains (kp, ki, kd) at the pre-shear force.
    start_step : int
        First step after the filling.
    compress_steps, preshear_steps, unload_steps, shear_steps : int
        Steps of one compression, pre-shear, unloading and shear.
    run_in_steps : int
        Steps the first pre-shear runs longer than the others (its readout window lies at its
        end): a freshly compressed bed reaches the steadily sheared state only after more
        travel than a later cycle, which starts from the state the earlier ones left.
    speed : float
        Speed of the lower part during pre-shear and shear, m/s.
    return_speed : float
        Speed of the return to zero offset between "return" cycles, m/s.
    unload_fraction : float
        Lid force while unloaded, as a fraction of ``force``, -.
    dt : float
        Time step, s.

    Returns
    -------
    Schedule
    """
    n_cycle_travel = preshear_steps + shear_steps
    line = Timeline(start_step, force, gains)
    line.add("phase 0: compress to the pre-shear load", 0, 0, force, compress_steps)
    if mode == "alternate":
        # The run-in adds to the first swing only: start that much further out, so that the
        # first cycle still ends at -h.
        n_pos = max(1, n_cycle_travel // 2 + run_in_steps)
        line.add("phase 0: move the lower part to +h under load", 0, 0, force, n_pos, speed, dt)
    cycles = []
    for k, p in enumerate(p_values):
        direction = 1 if (mode == "alternate" and k % 2 == 1) else -1
        towards = "-x" if direction < 0 else "+x"
        if mode == "return" and k > 0:
            line.add(f"cycle {k}: unload", 0, k, unload_fraction * force, unload_steps)
            back = (n_cycle_travel * speed * dt) / return_speed
            n_back = steps_for(back, dt)
            # Exactly back to zero offset in whole steps.
            v_back = -line.offset / (n_back * dt)
            line.add(
                f"cycle {k}: return to zero offset",
                0,
                k,
                unload_fraction * force,
                n_back,
                v_back,
                dt,
            )
            line.add(f"cycle {k}: compress to the pre-shear load", 0, k, force, compress_steps)
        pre = line.add(
            f"cycle {k}: pre-shear (P = {p:g}), lower part towards {towards}",
            1,
            k,
            force,
            preshear_steps + (run_in_steps if k == 0 else 0),
            direction * speed,
            dt,
            snapshot=k == 0,
        )
        line.add(f"cycle {k}: unload", 2, k, unload_fraction * force, unload_steps)
        sh = line.add(
            f"cycle {k}: shear at P = {p:g}", 3, k, p * force, shear_steps, direction * speed, dt
        )
        cycles.append(
            ShearCycle(
                index=k,
                P=p,
                direction=direction,
                preshear_force=force,
                shear_force=p * force,
                preshear_start_step=pre.start_step,
                preshear_end_step=pre.end_step,
                shear_start_step=sh.start_step,
                shear_end_step=sh.end_step,
                offset_preshear_start=pre.offset_start,
                offset_shear_end=sh.offset_end,
            )
        )
    return Schedule(segments=tuple(line.segments), cycles=tuple(cycles), end_step=line.step)
