"""ArduPilot's vehicles as the battery failsafe sees them: action tables, priority lists, fallbacks.

Each vehicle gives BATT_FS_LOW_ACT / BATT_FS_CRT_ACT its own meaning (the ``@Values{Vehicle}`` lines
of ``libraries/AP_BattMonitor/AP_BattMonitor_Params.cpp``), hands ``AP_BattMonitor`` a priority
list of its actions, highest first (``_failsafe_priorities`` in ``Rover/Rover.h``,
``ArduCopter/Copter.h``, ``ArduPlane/Plane.h``, ``ArduSub/Sub.h``), and runs an action through its
own handler, which falls back when a mode cannot be entered (``Rover::handle_battery_failsafe`` in
``Rover/failsafe.cpp``, ``Copter::do_failsafe_action`` in ``ArduCopter/events.cpp``,
``Plane::handle_battery_failsafe`` in ``ArduPlane/events.cpp``, ``Sub::handle_battery_failsafe``
in ``ArduSub/failsafe.cpp``). The tables are facts read from those files.

A parameter file shows its vehicle when it holds parameters only one vehicle has
(:func:`detect_vehicle`); otherwise the seed's vehicle, ``rover``, is assumed, and said.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

DEFAULT_VEHICLE = "rover"  # the seed (AN-00035) is about a rover


@dataclass(frozen=True)
class Situation:
    """What the fallback chains ask of the vehicle when an action runs."""

    home_set: bool = True
    position_fix: bool = True
    smart_rtl_ready: bool = True  # a SmartRTL path is recorded
    quadplane: bool = False  # Plane: a QuadPlane is available (Q_ENABLE = 1)
    landing_sequence: bool = False  # Plane/Copter: the mission holds a DO_LAND_START sequence

    @property
    def can_rtl(self) -> bool:
        return self.home_set and self.position_fix


@dataclass(frozen=True)
class Vehicle:
    name: str
    firmware: str  # ArduRover, ArduCopter...
    low_actions: Mapping[int, str]  # BATT_FS_LOW_ACT code -> ArduPilot's label
    critical_actions: Mapping[int, str]
    priorities: tuple[int, ...]  # action codes, highest priority first (the -1 sentinel left out)
    default_low_volt: float  # AP_BattMonitor_Params.cpp DEFAULT_LOW_BATTERY_VOLTAGE
    markers: frozenset[str] = field(default_factory=frozenset)  # parameters only this vehicle has

    def actions(self, level: str) -> Mapping[int, str]:
        return self.critical_actions if level == "critical" else self.low_actions

    def priority(self, action: int) -> int:
        """AP_BattMonitor::check_failsafes: the action's index in the list; an action the list
        lacks gets the sentinel's index (below every listed one)."""
        return self.priorities.index(action) if action in self.priorities else len(self.priorities)

    def resolve(self, action: int, situation: Situation) -> str:
        """What the vehicle ends up doing once its handler's fallback chain has run (a code the
        vehicle does not know: nothing, as no case of the handler's switch matches)."""
        if action not in self.low_actions and action not in self.critical_actions:
            return "none"
        return _RESOLVERS[self.name](action, situation)


def _rover(action: int, s: Situation) -> str:
    # Rover::handle_battery_failsafe: SmartRTL -> RTL -> Hold; SmartRTL_Hold -> Hold; Terminate disarms
    if action == 0:
        return "none"
    if action == 5:
        return "disarm"
    if action in (3, 4) and s.can_rtl and s.smart_rtl_ready:
        return "smart_rtl"
    if action in (3, 1) and s.can_rtl:
        return "rtl"
    return "hold"


def _copter(action: int, s: Situation) -> str:
    # Copter::do_failsafe_action: RTL -> Land; SmartRTL -> RTL -> Land; SmartRTL_Land -> Land;
    # Auto DO_LAND_START -> RTL -> Land; Terminate disarms
    if action == 0:
        return "none"
    if action == 5:
        return "disarm"
    if action == 1:
        return "land"
    if action in (3, 4) and s.can_rtl and s.smart_rtl_ready:
        return "smart_rtl"
    if action == 6 and s.landing_sequence and s.position_fix:
        return "auto_land"
    if action in (2, 3, 6) and s.can_rtl:
        return "rtl"
    return "land"


def _plane(action: int, s: Situation) -> str:
    # Plane::handle_battery_failsafe: Loiter to QLand -> QLand -> Land -> RTL; Land jumps to the
    # mission's landing sequence when there is one, else RTL; Terminate disarms; Parachute releases
    if action == 0:
        return "none"
    if action == 3:
        return "disarm"
    if action == 5:
        return "parachute"
    if action == 6 and s.quadplane:
        return "loiter_qland"
    if action in (4, 6) and s.quadplane:
        return "qland"
    if action in (2, 4, 6) and s.landing_sequence and s.position_fix:
        return "auto_land"
    return "rtl"


def _sub(action: int, s: Situation) -> str:
    # Sub::handle_battery_failsafe: Surface enters SURFACE mode, Disarm disarms, Warn/None nothing
    return {2: "disarm", 3: "surface"}.get(action, "none")


_RESOLVERS = {"rover": _rover, "copter": _copter, "plane": _plane, "sub": _sub}

_ROVER_ACTIONS = {0: "None", 1: "RTL", 2: "Hold", 3: "SmartRTL", 4: "SmartRTL or Hold", 5: "Terminate"}
_COPTER_ACTIONS = {0: "None", 1: "Land", 2: "RTL", 3: "SmartRTL or RTL", 4: "SmartRTL or Land", 5: "Terminate",
                   6: "Auto DO_LAND_START or RTL"}  # fmt: skip
_PLANE_LOW = {0: "None", 1: "RTL", 2: "Land", 3: "Terminate", 4: "QLand", 6: "Loiter to QLand"}
_PLANE_CRITICAL = {0: "None", 1: "RTL", 2: "Land", 3: "Terminate", 4: "QLand", 5: "Parachute", 6: "Loiter to QLand"}
_SUB_ACTIONS = {0: "None", 2: "Disarm", 3: "Enter surface mode"}

VEHICLES: dict[str, Vehicle] = {
    "rover": Vehicle(
        "rover",
        "ArduRover",
        _ROVER_ACTIONS,
        _ROVER_ACTIONS,
        # Terminate, Hold, RTL, SmartRTL_Hold, SmartRTL, None
        (5, 2, 1, 4, 3, 0),
        0.0,
        frozenset({"CRUISE_SPEED", "CRUISE_THROTTLE", "ATC_STR_RAT_P", "ATC_SPEED_P", "PIVOT_TURN_ANGLE"}),
    ),
    "copter": Vehicle(
        "copter",
        "ArduCopter",
        _COPTER_ACTIONS,
        _COPTER_ACTIONS,
        # TERMINATE, LAND, RTL, SMARTRTL_LAND, SMARTRTL, NONE (AUTO_DO_LAND_START is not listed)
        (5, 1, 2, 4, 3, 0),
        10.5,
        frozenset({"RTL_ALT", "LAND_SPEED", "LAND_ALT_LOW", "RTL_LOIT_TIME", "PHLD_BRAKE_RATE", "H_SW_TYPE"}),
    ),
    "plane": Vehicle(
        "plane",
        "ArduPlane",
        _PLANE_LOW,
        _PLANE_CRITICAL,
        # Terminate, Parachute, QLand, Land, RTL, None (Loiter_alt_QLand is not listed)
        (3, 5, 4, 2, 1, 0),
        0.0,
        frozenset(
            {
                "TRIM_ARSPD_CM",
                "AIRSPEED_CRUISE",
                "ARSPD_FBW_MIN",
                "ALT_HOLD_RTL",
                "TECS_CLMB_MAX",
                "Q_ENABLE",
                "RLL2SRV_P",
                "PTCH2SRV_P",
            }
        ),
    ),
    "sub": Vehicle(
        "sub",
        "ArduSub",
        _SUB_ACTIONS,
        _SUB_ACTIONS,
        # Disarm, Surface, Warn, None
        (2, 3, 1, 0),
        0.0,
        frozenset({"SURFACE_DEPTH", "JS_GAIN_DEFAULT", "FS_LEAK_ENABLE", "LEAK1_PIN", "BTN0_FUNCTION"}),
    ),
}


@dataclass(frozen=True)
class Detection:
    vehicle: Vehicle
    how: str  # the words saying where the vehicle came from


def vehicle(name: str) -> Vehicle:
    try:
        return VEHICLES[name]
    except KeyError:
        raise ValueError(f"expected a vehicle among {', '.join(VEHICLES)}, got {name!r}") from None


def detect_vehicle(names: Iterable[str], given: str | None = None) -> Detection:
    """The vehicle a parameter set belongs to: ``given`` when set; else the one vehicle whose own
    parameters appear; else rover (the seed's vehicle)."""
    if given:
        return Detection(vehicle(given), f"{given} (given)")
    present = set(names)
    found = {v.name: sorted(v.markers & present) for v in VEHICLES.values() if v.markers & present}
    if len(found) == 1:
        (name, seen), *_ = found.items()
        return Detection(VEHICLES[name], f"{name} (detected from {', '.join(seen[:3])}, which only {name} has)")
    if found:
        which = "; ".join(f"{n}: {', '.join(s[:2])}" for n, s in sorted(found.items()))
        return Detection(VEHICLES[DEFAULT_VEHICLE], f"{DEFAULT_VEHICLE} (assumed: parameters of several vehicles, "
                         f"{which}; give --vehicle)")  # fmt: skip
    return Detection(VEHICLES[DEFAULT_VEHICLE], f"{DEFAULT_VEHICLE} (assumed: no parameter only one vehicle has; "
                     "give --vehicle)")  # fmt: skip
