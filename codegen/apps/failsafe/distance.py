"""The seed's Phase 2 distance-aware trigger, an opt-in variant (ArduPilot has no such trigger).

Seed AN-00035, FR-DRAFT-5 ("Phase 2"): "Calculate consumption rate (mAh/meter or mAh/second)",
"Trigger RTL when remaining range < distance to home + margin", with the "Safety margin: 30%
recommended (multiply required by 1.3)". Here: LOW when the remaining charge no longer covers
``distance_to_home * rate * margin + reserve``; the rate is learned since arming (charge used over
distance travelled) once ``learn_after_m`` metres are seen, else the configured one.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class DistanceRule:
    margin: float = 1.3
    reserve_mah: float = 0.0
    consumption_mah_per_m: float | None = None
    learn_after_m: float = 20.0
    consumed_at_arm: float | None = None
    travelled_m: float = 0.0
    last_distance: float | None = None

    def rearm(self) -> None:
        self.consumed_at_arm, self.travelled_m, self.last_distance = None, 0.0, None

    def learn(self, consumed: float, distance: float | None, travelled: float | None) -> None:
        if self.consumed_at_arm is None:
            self.consumed_at_arm = consumed
        if travelled is not None:
            self.travelled_m = travelled
        elif distance is not None:
            if self.last_distance is not None:
                self.travelled_m += abs(distance - self.last_distance)
            self.last_distance = distance

    def rate(self, consumed: float) -> float | None:
        """mAh per metre: learned since arming once enough travel is seen, else the configured one."""
        if self.consumed_at_arm is not None and self.travelled_m >= self.learn_after_m:
            return max(consumed - self.consumed_at_arm, 0.0) / self.travelled_m
        return self.consumption_mah_per_m

    def needed(self, consumed: float, distance: float | None) -> float | None:
        """The charge needed to return, or None when the distance or the rate is unknown."""
        rate = self.rate(consumed)
        if distance is None or rate is None:
            return None
        return distance * rate * self.margin + self.reserve_mah
