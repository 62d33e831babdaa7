// Copied by battgen from codegen/backends/rust/support/failsafe.rs; do not edit.
//! The battery failsafe with ArduPilot's semantics (`AP_BattMonitor::check_failsafes`), fed one
//! sample at a time. It has no clock of its own: every sample carries its time in whole
//! milliseconds, as `AP_HAL::millis()` gives it, and times never go back.
//!
//! It restates battgen's Python evaluator (`codegen/apps/failsafe/`), which the crate's tests
//! replay it against, event for event:
//! - every reading goes through its battery's monitor (consumed charge: the reading's own, else
//!   the current integrated as the analog backend does, gaps of 2 s and more skipped; the
//!   internal resistance estimate of `update_resistance_estimate`); the failsafe is checked only
//!   while armed;
//! - a voltage below `BATT_CRT_VOLT` / `BATT_LOW_VOLT` (raw, or sag compensated with
//!   `BATT_FS_VOLTSRC` = 1) counts once it has lasted strictly more than `BATT_LOW_TIMER`
//!   (0 disables both voltage failsafes); the remaining charge `BATT_CAPACITY - consumed` counts
//!   at once, only when the monitor measures current; checked in the order CRITICAL voltage,
//!   CRITICAL capacity, LOW voltage, LOW capacity;
//! - a battery's level only rises and never clears (not on recovery, not on disarming);
//! - a new level takes its battery's `FS_LOW_ACT` / `FS_CRT_ACT`, and runs it only if its index in
//!   the vehicle's priority list is at most the highest priority already run by any battery; the
//!   vehicle's handler then falls back as it can ([`Outcome`]). A failsafe that disarms silences
//!   the evaluator until a disarmed sample.
//!
//! The seed's own choices are opt-in [`Variants`]: `seed-critical` (CRITICAL voltage at once and
//! its action always runs) and `distance` (LOW when the charge left no longer covers the way home
//! times a margin).
//!
//! ```
//! use battgen::failsafe::{Failsafe, Level, Reading, Sample, Settings, Variants, Vehicle};
//!
//! let mut settings = Settings::defaults(Vehicle::Rover);
//! settings.low_volt = 10.5;
//! settings.low_timer_s = 1.0;
//! settings.low_action = 2; // Rover: Hold
//! let mut fs = Failsafe::new(Vehicle::Rover, Variants::NONE);
//! fs.configure(1, settings).unwrap();
//! let sag = Sample::armed(Reading::volts(10.2));
//! assert_eq!(fs.update(0, 1, &sag), Ok(None)); // the timer starts
//! let event = fs.update(1_500, 1, &sag).unwrap().unwrap(); // 1.5 s > BATT_LOW_TIMER
//! assert_eq!(event.level, Level::Low);
//! assert_eq!(event.action_name(Vehicle::Rover), Some("Hold"));
//! ```

use core::fmt;

/// Battery monitors a vehicle has (`AP_BATT_MONITOR_MAX_INSTANCES`).
pub const MAX_INSTANCES: usize = 16;
/// `BATT_MONITOR` 0: no monitor.
pub const MONITOR_DISABLED: i32 = 0;
/// `BATT_MONITOR` 3: Analog Voltage Only (no current).
pub const MONITOR_VOLTAGE_ONLY: i32 = 3;
/// `BATT_FS_VOLTSRC` 1: Sag Compensated Voltage.
pub const VOLTSRC_RESTING: i32 = 1;
/// `_highest_failsafe_priority` after `AP_BattMonitor::init` (INT8_MAX).
pub const INITIAL_PRIORITY: usize = 127;

const RES_EST_TC_1: f64 = 0.5; // AP_BATT_MONITOR_RES_EST_TC_1
const RES_EST_TC_2: f64 = 0.1; // AP_BATT_MONITOR_RES_EST_TC_2
const FLT_EPSILON: f64 = 1.1920929e-07; // is_zero() / is_positive() in AP_Math
const MAX_INTEGRATION_MS: i64 = 2000; // AP_BattMonitor_Analog::read skips longer gaps
const MAH_PER_AMP_MS: f64 = 1.0 / 3600.0; // 1 A for 1 ms in mAh

// Python's max/min (the first argument unless the second is strictly beyond it) and abs, which
// core's f64 lacks without std; the evaluator being restated uses these exact semantics.
fn py_max(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

fn py_min(a: f64, b: f64) -> f64 {
    if b < a {
        b
    } else {
        a
    }
}

fn abs(x: f64) -> f64 {
    if x < 0.0 {
        -x
    } else {
        x
    }
}

/// Seconds to whole milliseconds, rounded half to even (Python's `round(s * 1000)`).
#[must_use]
pub fn millis(seconds: f64) -> i64 {
    let x = seconds * 1000.0;
    let (sign, x) = if x < 0.0 { (-1, -x) } else { (1, x) };
    let whole = x as i64; // truncates; saturates beyond i64
    let rest = x - whole as f64;
    let rounded = if rest > 0.5 || (rest == 0.5 && whole % 2 == 1) {
        whole + 1
    } else {
        whole
    };
    sign * rounded
}

/// A failsafe level; it only ever rises.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// No failsafe.
    None = 0,
    /// `BATT_LOW_VOLT` / `BATT_LOW_MAH` crossed.
    Low = 1,
    /// `BATT_CRT_VOLT` / `BATT_CRT_MAH` crossed.
    Critical = 2,
}

impl Level {
    /// As ArduPilot prints it in "Battery 1 is low".
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Level::None => "none",
            Level::Low => "low",
            Level::Critical => "critical",
        }
    }

    /// As uORB `battery_status.warning` carries it (`BATTERY_WARNING_*`).
    #[must_use]
    pub const fn uorb_warning(self) -> u8 {
        self as u8
    }

    /// As MAVLink `BATTERY_STATUS.charge_state` carries it (`MAV_BATTERY_CHARGE_STATE_*`).
    #[must_use]
    pub const fn mavlink_charge_state(self) -> u8 {
        self as u8 + 1
    }
}

/// The ArduPilot vehicles, each with its own meaning of the action codes, priority list and
/// fallbacks (`Rover::handle_battery_failsafe`, `Copter::do_failsafe_action`,
/// `Plane::handle_battery_failsafe`, `Sub::handle_battery_failsafe`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Vehicle {
    /// ArduRover.
    Rover,
    /// ArduCopter.
    Copter,
    /// ArduPlane.
    Plane,
    /// ArduSub.
    Sub,
}

impl Vehicle {
    /// The vehicle's name as battgen spells it (`rover`, `copter`, `plane`, `sub`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Vehicle::Rover => "rover",
            Vehicle::Copter => "copter",
            Vehicle::Plane => "plane",
            Vehicle::Sub => "sub",
        }
    }

    /// The vehicle of a battgen name.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Vehicle> {
        [
            Vehicle::Rover,
            Vehicle::Copter,
            Vehicle::Plane,
            Vehicle::Sub,
        ]
        .into_iter()
        .find(|v| v.name() == name)
    }

    /// The action codes handed to `AP_BattMonitor`, highest priority first (`_failsafe_priorities`,
    /// the -1 sentinel left out).
    #[must_use]
    pub const fn priorities(self) -> &'static [i32] {
        match self {
            Vehicle::Rover => &[5, 2, 1, 4, 3, 0],
            Vehicle::Copter => &[5, 1, 2, 4, 3, 0],
            Vehicle::Plane => &[3, 5, 4, 2, 1, 0],
            Vehicle::Sub => &[2, 3, 1, 0],
        }
    }

    /// `DEFAULT_LOW_BATTERY_VOLTAGE`: `BATT_LOW_VOLT`'s default.
    #[must_use]
    pub const fn default_low_volt(self) -> f64 {
        match self {
            Vehicle::Copter => 10.5,
            _ => 0.0,
        }
    }

    /// An action's index in the priority list; a code the list lacks gets the sentinel's index.
    #[must_use]
    pub fn priority(self, action: i32) -> usize {
        let list = self.priorities();
        list.iter().position(|&a| a == action).unwrap_or(list.len())
    }

    /// The action a `BATT_FS_LOW_ACT` (`critical` false) or `BATT_FS_CRT_ACT` code means on this
    /// vehicle (the `@Values{Vehicle}` of `AP_BattMonitor_Params.cpp`), None for a code it lacks.
    #[must_use]
    pub const fn action(self, critical: bool, code: i32) -> Option<Action> {
        use Action as A;
        use Vehicle as V;
        Some(match (self, code) {
            (_, 0) => A::None,
            (V::Rover, 1) | (V::Copter, 2) | (V::Plane, 1) => A::Rtl,
            (V::Rover, 2) => A::Hold,
            (V::Rover, 3) => A::SmartRtl,
            (V::Rover, 4) => A::SmartRtlOrHold,
            (V::Rover, 5) | (V::Copter, 5) | (V::Plane, 3) => A::Terminate,
            (V::Copter, 1) | (V::Plane, 2) => A::Land,
            (V::Copter, 3) => A::SmartRtlOrRtl,
            (V::Copter, 4) => A::SmartRtlOrLand,
            (V::Copter, 6) => A::AutoDoLandStartOrRtl,
            (V::Plane, 4) => A::Qland,
            (V::Plane, 5) if critical => A::Parachute,
            (V::Plane, 6) => A::LoiterToQland,
            (V::Sub, 2) => A::Disarm,
            (V::Sub, 3) => A::Surface,
            _ => return None,
        })
    }

    /// The code of an action on this vehicle (`critical`: as `BATT_FS_CRT_ACT`), None when the
    /// vehicle has no such action.
    #[must_use]
    pub fn code(self, critical: bool, action: Action) -> Option<i32> {
        (0..=6).find(|&c| self.action(critical, c) == Some(action))
    }

    /// ArduPilot's label of a `BATT_FS_LOW_ACT` (`critical` false) or `BATT_FS_CRT_ACT` code.
    #[must_use]
    pub const fn action_name(self, critical: bool, code: i32) -> Option<&'static str> {
        match self.action(critical, code) {
            Some(action) => Some(action.label()),
            None => None,
        }
    }

    /// What the vehicle ends up doing once its handler's fallback chain has run; a code the
    /// vehicle does not know does nothing (no case of the handler's switch matches).
    #[must_use]
    pub fn resolve(self, action: i32, s: &Situation) -> Outcome {
        if self.action_name(false, action).is_none() && self.action_name(true, action).is_none() {
            return Outcome::None;
        }
        let rtl = s.can_rtl();
        match self {
            // SmartRTL -> RTL -> Hold; SmartRTL_Hold -> Hold; Terminate disarms
            Vehicle::Rover => match action {
                0 => Outcome::None,
                5 => Outcome::Disarm,
                3 | 4 if rtl && s.smart_rtl_ready => Outcome::SmartRtl,
                3 | 1 if rtl => Outcome::Rtl,
                _ => Outcome::Hold,
            },
            // RTL -> Land; SmartRTL -> RTL -> Land; SmartRTL_Land -> Land; Auto DO_LAND_START -> RTL -> Land
            Vehicle::Copter => match action {
                0 => Outcome::None,
                5 => Outcome::Disarm,
                1 => Outcome::Land,
                3 | 4 if rtl && s.smart_rtl_ready => Outcome::SmartRtl,
                6 if s.landing_sequence && s.position_fix => Outcome::AutoLand,
                2 | 3 | 6 if rtl => Outcome::Rtl,
                _ => Outcome::Land,
            },
            // Loiter to QLand -> QLand -> Land -> RTL; Land takes the mission's landing sequence
            Vehicle::Plane => match action {
                0 => Outcome::None,
                3 => Outcome::Disarm,
                5 => Outcome::Parachute,
                6 if s.quadplane => Outcome::LoiterQland,
                4 | 6 if s.quadplane => Outcome::Qland,
                2 | 4 | 6 if s.landing_sequence && s.position_fix => Outcome::AutoLand,
                _ => Outcome::Rtl,
            },
            Vehicle::Sub => match action {
                2 => Outcome::Disarm,
                3 => Outcome::Surface,
                _ => Outcome::None,
            },
        }
    }
}

/// A battery failsafe action, as the vehicles' `@Values` name them; [`Vehicle::action`] gives a
/// code's action on a vehicle, [`Vehicle::code`] the way back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// No action.
    None,
    /// Return to launch.
    Rtl,
    /// Rover: hold.
    Hold,
    /// Rover: SmartRTL, else RTL, else Hold.
    SmartRtl,
    /// Rover: SmartRTL, else Hold.
    SmartRtlOrHold,
    /// Disarm at once.
    Terminate,
    /// Land where it is.
    Land,
    /// Copter: SmartRTL, else RTL.
    SmartRtlOrRtl,
    /// Copter: SmartRTL, else Land.
    SmartRtlOrLand,
    /// Copter: the mission's DO_LAND_START, else RTL.
    AutoDoLandStartOrRtl,
    /// Plane: QuadPlane land.
    Qland,
    /// Plane: loiter down, then QuadPlane land.
    LoiterToQland,
    /// Plane: release the parachute (CRITICAL only).
    Parachute,
    /// Sub: disarm.
    Disarm,
    /// Sub: surface.
    Surface,
}

impl Action {
    /// ArduPilot's label (`@Values{Vehicle}`).
    #[must_use]
    pub const fn label(self) -> &'static str {
        match self {
            Action::None => "None",
            Action::Rtl => "RTL",
            Action::Hold => "Hold",
            Action::SmartRtl => "SmartRTL",
            Action::SmartRtlOrHold => "SmartRTL or Hold",
            Action::Terminate => "Terminate",
            Action::Land => "Land",
            Action::SmartRtlOrRtl => "SmartRTL or RTL",
            Action::SmartRtlOrLand => "SmartRTL or Land",
            Action::AutoDoLandStartOrRtl => "Auto DO_LAND_START or RTL",
            Action::Qland => "QLand",
            Action::LoiterToQland => "Loiter to QLand",
            Action::Parachute => "Parachute",
            Action::Disarm => "Disarm",
            Action::Surface => "Enter surface mode",
        }
    }
}

/// Battery `instance`'s (1-based) parameter prefix: `BATT_`, `BATT2_` .. `BATT9_`, `BATTA_` ..
/// `BATTG_` (`AP_BattMonitor.cpp` `var_info`).
#[must_use]
pub const fn battery_prefix(instance: u8) -> Option<&'static str> {
    const PREFIXES: [&str; MAX_INSTANCES] = [
        "BATT_", "BATT2_", "BATT3_", "BATT4_", "BATT5_", "BATT6_", "BATT7_", "BATT8_", "BATT9_",
        "BATTA_", "BATTB_", "BATTC_", "BATTD_", "BATTE_", "BATTF_", "BATTG_",
    ];
    match instance {
        1..=16 => Some(PREFIXES[instance as usize - 1]),
        _ => None,
    }
}

/// A `BATT*_` parameter name split into its battery (1-based) and battery 1's name of it
/// (`BATT2_LOW_VOLT` -> `(2, "LOW_VOLT")`); None for other names.
#[must_use]
pub fn split_battery_name(name: &str) -> Option<(u8, &str)> {
    (1..=MAX_INSTANCES as u8).find_map(|i| {
        let rest = name.strip_prefix(battery_prefix(i)?)?;
        let ok = !rest.is_empty()
            && rest
                .bytes()
                .all(|b| b.is_ascii_uppercase() || b.is_ascii_digit() || b == b'_');
        ok.then_some((i, rest))
    })
}

/// What the vehicle does once a failsafe's action has gone through its handler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The priority rule did not let the action run.
    NotRun,
    /// Nothing (action None, Warn, or a code the vehicle does not know).
    None,
    /// Disarmed (Terminate, Sub's Disarm).
    Disarm,
    /// SMART_RTL mode.
    SmartRtl,
    /// RTL mode.
    Rtl,
    /// HOLD mode.
    Hold,
    /// LAND mode.
    Land,
    /// AUTO mode at the mission's DO_LAND_START.
    AutoLand,
    /// Plane: LOITER then QLAND.
    LoiterQland,
    /// Plane: QLAND.
    Qland,
    /// Plane: parachute released.
    Parachute,
    /// Sub: SURFACE mode.
    Surface,
}

impl Outcome {
    /// battgen's name of the outcome (`not run`, `rtl`, `smart_rtl`, ...).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Outcome::NotRun => "not run",
            Outcome::None => "none",
            Outcome::Disarm => "disarm",
            Outcome::SmartRtl => "smart_rtl",
            Outcome::Rtl => "rtl",
            Outcome::Hold => "hold",
            Outcome::Land => "land",
            Outcome::AutoLand => "auto_land",
            Outcome::LoiterQland => "loiter_qland",
            Outcome::Qland => "qland",
            Outcome::Parachute => "parachute",
            Outcome::Surface => "surface",
        }
    }
}

/// What the fallback chains ask of the vehicle when an action runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Situation {
    /// Home is set.
    pub home_set: bool,
    /// The vehicle has a position.
    pub position_fix: bool,
    /// A SmartRTL path is recorded.
    pub smart_rtl_ready: bool,
    /// Plane: a QuadPlane is available (`Q_ENABLE` = 1).
    pub quadplane: bool,
    /// The mission holds a DO_LAND_START sequence.
    pub landing_sequence: bool,
}

impl Situation {
    /// Home set, position known, SmartRTL ready, no QuadPlane, no landing sequence.
    pub const DEFAULT: Situation = Situation {
        home_set: true,
        position_fix: true,
        smart_rtl_ready: true,
        quadplane: false,
        landing_sequence: false,
    };

    /// RTL can be entered.
    #[must_use]
    pub const fn can_rtl(&self) -> bool {
        self.home_set && self.position_fix
    }
}

impl Default for Situation {
    fn default() -> Self {
        Situation::DEFAULT
    }
}

/// One battery's `BATT*_` failsafe parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// `BATT_CAPACITY`, mAh.
    pub capacity_mah: f64,
    /// `BATT_LOW_VOLT`, V (0: off).
    pub low_volt: f64,
    /// `BATT_LOW_TIMER`, s (0: both voltage failsafes off).
    pub low_timer_s: f64,
    /// `BATT_LOW_MAH`, mAh (0: off).
    pub low_mah: f64,
    /// `BATT_CRT_VOLT`, V (0: off).
    pub crt_volt: f64,
    /// `BATT_CRT_MAH`, mAh (0: off).
    pub crt_mah: f64,
    /// `BATT_FS_LOW_ACT`.
    pub low_action: i32,
    /// `BATT_FS_CRT_ACT`.
    pub crt_action: i32,
    /// `BATT_FS_VOLTSRC` (1: sag compensated).
    pub volt_source: i32,
    /// `BATT_MONITOR`; None when unknown (the readings decide whether current is measured).
    pub monitor: Option<i32>,
}

impl Settings {
    /// ArduPilot's defaults (`AP_BattMonitor_Params.cpp`) on a vehicle.
    #[must_use]
    pub const fn defaults(vehicle: Vehicle) -> Settings {
        Settings {
            capacity_mah: 3300.0,
            low_volt: vehicle.default_low_volt(),
            low_timer_s: 10.0,
            low_mah: 0.0,
            crt_volt: 0.0,
            crt_mah: 0.0,
            low_action: 0,
            crt_action: 0,
            volt_source: 0,
            monitor: None,
        }
    }

    /// One battery's settings from a parameter set: `get` gives a parameter's value by battery 1's
    /// name without the `BATT_` prefix (`LOW_VOLT`), None when absent (ArduPilot's default).
    ///
    /// # Errors
    /// The field whose value is not finite, or not an integer where a code is expected.
    pub fn from_params(
        vehicle: Vehicle,
        mut get: impl FnMut(&str) -> Option<f64>,
    ) -> Result<Settings, &'static str> {
        let d = Settings::defaults(vehicle);
        let mut number = |field: &'static str, default: f64| match get(field) {
            None => Ok(default),
            Some(v) if v.is_finite() => Ok(v),
            Some(_) => Err(field),
        };
        let capacity_mah = number("CAPACITY", d.capacity_mah)?;
        let low_volt = number("LOW_VOLT", d.low_volt)?;
        let low_timer_s = number("LOW_TIMER", d.low_timer_s)?;
        let low_mah = number("LOW_MAH", d.low_mah)?;
        let crt_volt = number("CRT_VOLT", d.crt_volt)?;
        let crt_mah = number("CRT_MAH", d.crt_mah)?;
        let mut code = |field: &'static str| -> Result<Option<i32>, &'static str> {
            match get(field) {
                None => Ok(None),
                Some(v) if v.is_finite() && v == (v as i32) as f64 => Ok(Some(v as i32)),
                Some(_) => Err(field),
            }
        };
        Ok(Settings {
            capacity_mah,
            low_volt,
            low_timer_s,
            low_mah,
            crt_volt,
            crt_mah,
            low_action: code("FS_LOW_ACT")?.unwrap_or(0),
            crt_action: code("FS_CRT_ACT")?.unwrap_or(0),
            volt_source: code("FS_VOLTSRC")?.unwrap_or(0),
            monitor: code("MONITOR")?,
        })
    }

    /// `BATT_MONITOR` is not 0.
    #[must_use]
    pub fn enabled(&self) -> bool {
        self.monitor != Some(MONITOR_DISABLED)
    }

    fn voltage_only(&self) -> bool {
        self.monitor == Some(MONITOR_VOLTAGE_ONLY)
    }
}

/// One battery measurement; None (or a voltage of 0 or less, or not finite) means unknown.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reading {
    /// Pack voltage, V.
    pub voltage_v: Option<f64>,
    /// Current, A (positive when discharging).
    pub current_a: Option<f64>,
    /// Charge used, mAh.
    pub consumed_mah: Option<f64>,
    /// Charge left, mAh.
    pub remaining_mah: Option<f64>,
}

impl Reading {
    /// A reading of the voltage alone.
    #[must_use]
    pub const fn volts(voltage_v: f64) -> Reading {
        Reading {
            voltage_v: Some(voltage_v),
            current_a: None,
            consumed_mah: None,
            remaining_mah: None,
        }
    }
}

/// A reading with what the vehicle's state says at its time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// The battery's reading.
    pub reading: Reading,
    /// The vehicle is armed.
    pub armed: bool,
    /// Distance to home, m (the `distance` variant).
    pub distance_to_home_m: Option<f64>,
    /// Distance travelled since arming, m (the `distance` variant; else learned from the distance
    /// to home).
    pub travelled_m: Option<f64>,
    /// Home is set (None: as the failsafe's [`Situation`] says).
    pub home_set: Option<bool>,
    /// The vehicle has a position (None: as the failsafe's [`Situation`] says).
    pub position_fix: Option<bool>,
}

impl Sample {
    /// An armed sample of a reading, nothing else known.
    #[must_use]
    pub fn armed(reading: Reading) -> Sample {
        Sample {
            reading,
            armed: true,
            ..Sample::default()
        }
    }
}

/// The seed's opt-in variants (battgen's `--variant` names).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Variants {
    /// `seed-critical`: CRITICAL voltage at once (no `BATT_LOW_TIMER`) and its action always runs.
    pub seed_critical: bool,
    /// `distance`: LOW when the charge left no longer covers the way home times a margin.
    pub distance: bool,
}

impl Variants {
    /// ArduPilot's semantics, no variant.
    pub const NONE: Variants = Variants {
        seed_critical: false,
        distance: false,
    };
}

/// The seed's distance-aware trigger (`distance` variant): the charge needed to return is
/// `distance_to_home * rate * margin + reserve`, the rate learned since arming (charge used over
/// distance travelled) once `learn_after_m` metres are seen, else the configured one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistanceRule {
    /// Safety margin (the seed's 30 %: 1.3).
    pub margin: f64,
    /// Charge kept in reserve, mAh.
    pub reserve_mah: f64,
    /// The rate until one is learned, mAh per metre.
    pub consumption_mah_per_m: Option<f64>,
    /// Metres travelled before the learned rate is used.
    pub learn_after_m: f64,
    consumed_at_arm: Option<f64>,
    travelled_m: f64,
    last_distance: Option<f64>,
}

impl DistanceRule {
    /// Margin 1.3, no reserve, no configured rate, learned after 20 m.
    pub const DEFAULT: DistanceRule = DistanceRule {
        margin: 1.3,
        reserve_mah: 0.0,
        consumption_mah_per_m: None,
        learn_after_m: 20.0,
        consumed_at_arm: None,
        travelled_m: 0.0,
        last_distance: None,
    };

    fn rearm(&mut self) {
        self.consumed_at_arm = None;
        self.travelled_m = 0.0;
        self.last_distance = None;
    }

    fn learn(&mut self, consumed: f64, distance: Option<f64>, travelled: Option<f64>) {
        if self.consumed_at_arm.is_none() {
            self.consumed_at_arm = Some(consumed);
        }
        if let Some(travelled) = travelled {
            self.travelled_m = travelled;
        } else if let Some(distance) = distance {
            if let Some(last) = self.last_distance {
                self.travelled_m += abs(distance - last);
            }
            self.last_distance = Some(distance);
        }
    }

    /// mAh per metre: learned since arming once enough travel is seen, else the configured one.
    fn rate(&self, consumed: f64) -> Option<f64> {
        match self.consumed_at_arm {
            Some(at_arm) if self.travelled_m >= self.learn_after_m => {
                Some(py_max(consumed - at_arm, 0.0) / self.travelled_m)
            }
            _ => self.consumption_mah_per_m,
        }
    }

    fn needed(&self, consumed: f64, distance: Option<f64>) -> Option<f64> {
        let rate = self.rate(consumed)?;
        Some(distance? * rate * self.margin + self.reserve_mah)
    }
}

impl Default for DistanceRule {
    fn default() -> Self {
        DistanceRule::DEFAULT
    }
}

/// `update_resistance_estimate`: the pack's internal resistance from how the voltage falls as the
/// current rises, and the resting voltage `V + I * R`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct ResistanceEstimator {
    resistance: f64,
    resting_voltage: f64,
    voltage_filt: f64,
    current_filt: f64,
    current_max: f64,
    voltage_ref: f64,
    current_ref: f64,
    timer_ms: i64,
}

impl ResistanceEstimator {
    fn update(&mut self, now_ms: i64, voltage: f64, current: Option<f64>) {
        let Some(current) = current else { return };
        if current < FLT_EPSILON {
            return;
        }
        self.current_max = py_max(self.current_max, current);
        let delta = current - self.current_filt;
        if abs(delta) < FLT_EPSILON {
            return;
        }
        if voltage > self.voltage_ref {
            self.voltage_ref = voltage;
            self.current_ref = current;
        }
        let interval = (now_ms - self.timer_ms) as f64 / 1000.0;
        self.timer_ms = now_ms;
        let filt_alpha = py_min(py_max(interval / (interval + RES_EST_TC_1), 0.0), 0.5);
        let resistance_alpha = py_min(
            1.0,
            RES_EST_TC_2 * abs((current - self.current_filt) / self.current_max),
        );
        let estimate = -(voltage - self.voltage_filt) / delta;
        if estimate >= FLT_EPSILON {
            self.resistance =
                self.resistance * (1.0 - resistance_alpha) + estimate * resistance_alpha;
        }
        if self.voltage_ref > voltage && current > self.current_ref {
            self.resistance = py_min(
                self.resistance,
                (self.voltage_ref - voltage) / (current - self.current_ref),
            );
        }
        self.voltage_filt = self.voltage_filt * (1.0 - filt_alpha) + voltage * filt_alpha;
        self.current_filt = self.current_filt * (1.0 - filt_alpha) + current * filt_alpha;
        self.resting_voltage = voltage + current * self.resistance;
    }
}

/// Which check fired.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cause {
    /// The voltage (raw or resting) fell below its threshold for longer than the timer.
    Voltage,
    /// The remaining charge fell below its threshold.
    Capacity,
    /// The `distance` variant: the charge left no longer covers the way home.
    Distance,
}

impl Cause {
    /// battgen's name of the cause.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Cause::Voltage => "voltage",
            Cause::Capacity => "capacity",
            Cause::Distance => "distance",
        }
    }
}

#[derive(Clone, Copy)]
struct Trigger {
    level: Level,
    cause: Cause,
    value: f64,
    threshold: f64,
}

/// One battery monitor as `AP_BattMonitor_Backend` keeps it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Monitor {
    settings: Settings,
    voltage: f64, // 0: unknown, as ArduPilot's state.voltage
    current: Option<f64>,
    consumed_mah: f64,
    measures_current: bool,
    failsafe: Level,
    low_start_ms: Option<i64>,
    critical_start_ms: Option<i64>,
    last_ms: Option<i64>,
    estimator: ResistanceEstimator,
}

impl Monitor {
    fn new(settings: Settings) -> Monitor {
        Monitor {
            settings,
            voltage: 0.0,
            current: None,
            consumed_mah: 0.0,
            measures_current: false,
            failsafe: Level::None,
            low_start_ms: None,
            critical_start_ms: None,
            last_ms: None,
            estimator: ResistanceEstimator::default(),
        }
    }

    fn read(&mut self, now_ms: i64, r: &Reading) {
        let s = &self.settings;
        self.voltage = match r.voltage_v {
            Some(v) if v.is_finite() && v > 0.0 => v,
            _ => 0.0,
        };
        self.measures_current = !s.voltage_only()
            && (r.current_a.is_some() || r.consumed_mah.is_some() || r.remaining_mah.is_some());
        self.current = if s.voltage_only() { None } else { r.current_a };
        if let Some(consumed) = r.consumed_mah {
            self.consumed_mah = consumed;
        } else if let (Some(remaining), true) = (r.remaining_mah, s.capacity_mah > 0.0) {
            self.consumed_mah = s.capacity_mah - remaining;
        } else if let (Some(current), Some(last)) = (self.current, self.last_ms) {
            let dt = now_ms - last;
            if 0 < dt && dt < MAX_INTEGRATION_MS {
                self.consumed_mah += current * dt as f64 * MAH_PER_AMP_MS;
            }
        }
        self.last_ms = Some(now_ms);
        if self.measures_current {
            self.estimator.update(now_ms, self.voltage, self.current);
        }
    }

    fn remaining_mah(&self) -> f64 {
        self.settings.capacity_mah - self.consumed_mah
    }

    /// `check_failsafe_types`: the raw voltage, or the resting estimate (never below the raw one).
    fn voltage_used(&self) -> f64 {
        if self.settings.volt_source == VOLTSRC_RESTING {
            py_max(self.voltage, self.estimator.resting_voltage)
        } else {
            self.voltage
        }
    }

    fn update_failsafes(&mut self, now_ms: i64, critical_timer: bool) -> Option<Trigger> {
        let s = self.settings;
        let volts = self.voltage_used();
        let critical_voltage = volts > 0.0 && s.crt_volt > 0.0 && volts < s.crt_volt;
        let low_voltage = volts > 0.0 && s.low_volt > 0.0 && volts < s.low_volt;
        let remaining = self.remaining_mah();
        let critical_capacity = self.measures_current && s.crt_mah > 0.0 && remaining < s.crt_mah;
        let low_capacity = self.measures_current && s.low_mah > 0.0 && remaining < s.low_mah;
        let timeout_ms = millis(s.low_timer_s);
        let trigger = |level, cause, value, threshold| {
            Some(Trigger {
                level,
                cause,
                value,
                threshold,
            })
        };

        if critical_voltage {
            if !critical_timer {
                return trigger(Level::Critical, Cause::Voltage, volts, s.crt_volt);
            }
            match self.critical_start_ms {
                None => self.critical_start_ms = Some(now_ms),
                Some(start) if timeout_ms > 0 && now_ms - start > timeout_ms => {
                    return trigger(Level::Critical, Cause::Voltage, volts, s.crt_volt);
                }
                Some(_) => {}
            }
        } else {
            self.critical_start_ms = None;
        }
        if critical_capacity {
            return trigger(Level::Critical, Cause::Capacity, remaining, s.crt_mah);
        }
        if low_voltage {
            match self.low_start_ms {
                None => self.low_start_ms = Some(now_ms),
                Some(start) if timeout_ms > 0 && now_ms - start > timeout_ms => {
                    return trigger(Level::Low, Cause::Voltage, volts, s.low_volt);
                }
                Some(_) => {}
            }
        } else {
            self.low_start_ms = None;
        }
        if low_capacity {
            return trigger(Level::Low, Cause::Capacity, remaining, s.low_mah);
        }
        None
    }
}

/// A failsafe transition of one battery.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Event {
    /// The sample's time, ms.
    pub time_ms: u32,
    /// The battery, 1-based as ArduPilot prints it.
    pub battery: u8,
    /// The new level.
    pub level: Level,
    /// Which check fired.
    pub cause: Cause,
    /// V for voltage; remaining mAh for capacity and distance.
    pub value: f64,
    /// The parameter crossed (V / mAh), or the mAh needed to return.
    pub threshold: f64,
    /// The `FS_LOW_ACT` / `FS_CRT_ACT` value.
    pub action_code: i32,
    /// The priority rule let the action run.
    pub executed: bool,
    /// What the vehicle does after its handler's fallbacks.
    pub outcome: Outcome,
    /// The action's index in the vehicle's priority list.
    pub priority: usize,
    /// The raw voltage, V (what ArduPilot prints).
    pub voltage: f64,
    /// The charge used, mAh.
    pub consumed_mah: f64,
    /// The sag compensated voltage was compared (`BATT_FS_VOLTSRC` = 1, a voltage cause).
    pub resting_voltage: bool,
}

impl Event {
    /// ArduPilot's label of the event's action on `vehicle`, None for a code it does not know.
    #[must_use]
    pub const fn action_name(&self, vehicle: Vehicle) -> Option<&'static str> {
        vehicle.action_name(matches!(self.level, Level::Critical), self.action_code)
    }

    /// The STATUSTEXT as `AP_BattMonitor::check_failsafes` sends it:
    /// `Battery 1 is low 10.40V used 2500 mAh`.
    #[must_use]
    pub const fn ardupilot_text(&self) -> ArduPilotText {
        ArduPilotText(*self)
    }
}

/// [`Event::ardupilot_text`], written by `Display` (no allocation).
#[derive(Clone, Copy, Debug)]
pub struct ArduPilotText(Event);

impl fmt::Display for ArduPilotText {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let e = &self.0;
        write!(
            f,
            "Battery {} is {} {:.2}V used {:.0} mAh",
            e.battery,
            e.level.name(),
            e.voltage,
            e.consumed_mah
        )
    }
}

/// Why a sample was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error {
    /// A sample's time before the previous one's (ms).
    TimeWentBack {
        /// The sample's time.
        now_ms: u32,
        /// The previous sample's time.
        last_ms: u32,
    },
    /// A battery instance outside 1..=16.
    Instance(u8),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::TimeWentBack { now_ms, last_ms } => write!(
                f,
                "expected sample times that never go back, got {now_ms} ms after {last_ms} ms"
            ),
            Error::Instance(i) => write!(
                f,
                "expected a battery instance from 1 to {MAX_INSTANCES}, got {i}"
            ),
        }
    }
}

/// The failsafe over every battery of a vehicle.
#[derive(Clone, Debug)]
pub struct Failsafe {
    vehicle: Vehicle,
    variants: Variants,
    /// What the fallback chains ask of the vehicle (a sample may override home and position).
    pub situation: Situation,
    /// The `distance` variant's rule.
    pub distance_rule: DistanceRule,
    highest_priority: usize,
    monitors: [Monitor; MAX_INSTANCES],
    last_ms: Option<u32>,
    armed: bool,
    terminated: bool,
}

impl Failsafe {
    /// A failsafe whose batteries all have ArduPilot's defaults on `vehicle`.
    #[must_use]
    pub fn new(vehicle: Vehicle, variants: Variants) -> Failsafe {
        Failsafe {
            vehicle,
            variants,
            situation: Situation::DEFAULT,
            distance_rule: DistanceRule::DEFAULT,
            highest_priority: INITIAL_PRIORITY,
            monitors: [Monitor::new(Settings::defaults(vehicle)); MAX_INSTANCES],
            last_ms: None,
            armed: false,
            terminated: false,
        }
    }

    /// Sets battery `instance`'s (1-based) parameters, before its first sample.
    ///
    /// # Errors
    /// [`Error::Instance`] outside 1..=16.
    pub fn configure(&mut self, instance: u8, settings: Settings) -> Result<(), Error> {
        let i = Self::index(instance)?;
        self.monitors[i] = Monitor::new(settings);
        Ok(())
    }

    fn index(instance: u8) -> Result<usize, Error> {
        match instance as usize {
            i @ 1..=MAX_INSTANCES => Ok(i - 1),
            _ => Err(Error::Instance(instance)),
        }
    }

    /// The vehicle.
    #[must_use]
    pub const fn vehicle(&self) -> Vehicle {
        self.vehicle
    }

    /// The highest level of any battery.
    #[must_use]
    pub fn level(&self) -> Level {
        self.monitors
            .iter()
            .map(|m| m.failsafe)
            .max()
            .unwrap_or(Level::None)
    }

    /// Battery `instance`'s (1-based) level.
    #[must_use]
    pub fn battery_level(&self, instance: u8) -> Option<Level> {
        Self::index(instance)
            .ok()
            .map(|i| self.monitors[i].failsafe)
    }

    /// The highest priority run so far (127 before any).
    #[must_use]
    pub const fn highest_priority(&self) -> usize {
        self.highest_priority
    }

    /// One sample of battery `instance` (1-based) at `now_ms`: the event it causes, if any.
    ///
    /// # Errors
    /// A time before the previous sample's, or an instance outside 1..=16.
    pub fn update(
        &mut self,
        now_ms: u32,
        instance: u8,
        sample: &Sample,
    ) -> Result<Option<Event>, Error> {
        if let Some(last_ms) = self.last_ms {
            if now_ms < last_ms {
                return Err(Error::TimeWentBack { now_ms, last_ms });
            }
        }
        self.last_ms = Some(now_ms);
        let i = Self::index(instance)?;
        let now = i64::from(now_ms);
        let mon = &mut self.monitors[i];
        if !mon.settings.enabled() {
            return Ok(None); // BATTn_MONITOR = 0: ArduPilot has no monitor for it
        }
        mon.read(now, &sample.reading);
        if self.terminated {
            // the failsafe disarmed the vehicle: silent until the samples agree
            if sample.armed {
                return Ok(None);
            }
            self.terminated = false;
        }
        if !sample.armed {
            self.armed = false;
            return Ok(None);
        }
        if !self.armed {
            self.armed = true;
            self.distance_rule.rearm();
        }
        let situation = Situation {
            home_set: sample.home_set.unwrap_or(self.situation.home_set),
            position_fix: sample.position_fix.unwrap_or(self.situation.position_fix),
            ..self.situation
        };
        let mut trigger = mon.update_failsafes(now, !self.variants.seed_critical);
        if self.variants.distance && mon.measures_current {
            self.distance_rule.learn(
                mon.consumed_mah,
                sample.distance_to_home_m,
                sample.travelled_m,
            );
            if trigger.is_none() {
                let needed = self
                    .distance_rule
                    .needed(mon.consumed_mah, sample.distance_to_home_m);
                if let Some(needed) = needed {
                    let remaining = mon.remaining_mah();
                    if remaining <= needed {
                        trigger = Some(Trigger {
                            level: Level::Low,
                            cause: Cause::Distance,
                            value: remaining,
                            threshold: needed,
                        });
                    }
                }
            }
        }
        match trigger {
            Some(t) if t.level > mon.failsafe => Ok(Some(self.fire(now_ms, i, t, &situation))),
            _ => Ok(None),
        }
    }

    fn fire(&mut self, now_ms: u32, i: usize, trigger: Trigger, situation: &Situation) -> Event {
        let mon = &mut self.monitors[i];
        let s = mon.settings;
        let level = trigger.level;
        mon.failsafe = level;
        let code = if level == Level::Critical {
            s.crt_action
        } else {
            s.low_action
        };
        let priority = self.vehicle.priority(code);
        // FR-DRAFT-2 of the seed: "CRITICAL overrides LOW action"
        let executed = priority <= self.highest_priority
            || (self.variants.seed_critical && level == Level::Critical);
        let mut outcome = Outcome::NotRun;
        if executed {
            self.highest_priority = priority;
            outcome = self.vehicle.resolve(code, situation);
            if outcome == Outcome::Disarm {
                self.terminated = true;
            }
        }
        Event {
            time_ms: now_ms,
            battery: i as u8 + 1,
            level,
            cause: trigger.cause,
            value: trigger.value,
            threshold: trigger.threshold,
            action_code: code,
            executed,
            outcome,
            priority,
            voltage: mon.voltage,
            consumed_mah: mon.consumed_mah,
            resting_voltage: s.volt_source == VOLTSRC_RESTING && trigger.cause == Cause::Voltage,
        }
    }
}
