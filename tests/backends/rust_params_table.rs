//! Prints the crate's parameter table and per-vehicle failsafe tables as lines, for the Python side
//! (tests/backends/test_rust_params.py) to compare with the Python package's table and battgen's vehicles.

use battgen::failsafe::{battery_prefix, split_battery_name, Settings, Situation, Vehicle};
use battgen::params::{find, BATT};

fn bits(value: Option<f64>) -> String {
    value.map_or("-".to_string(), |v| format!("{:016x}", v.to_bits()))
}

#[test]
fn print_tables() {
    let mut out = Vec::new();
    for p in BATT {
        let values: Vec<String> = p.values.iter().map(|(c, _)| c.to_string()).collect();
        out.push(format!(
            "param {} {} {} {} {} {} {}",
            p.name,
            p.type_name,
            bits(Some(p.default)),
            bits(p.minimum),
            bits(p.maximum),
            p.unit.unwrap_or("-"),
            values.join(",")
        ));
        assert_eq!(find(BATT, p.name), Some(p));
        assert!(p.in_range(p.default), "{} default out of its range", p.name);
    }
    for v in [Vehicle::Rover, Vehicle::Copter, Vehicle::Plane, Vehicle::Sub] {
        let d = Settings::defaults(v);
        out.push(format!(
            "defaults {} {} {} {}",
            v.name(),
            bits(Some(d.capacity_mah)),
            bits(Some(d.low_volt)),
            bits(Some(d.low_timer_s))
        ));
        // Settings::from_params on the parameter sets the Python side reads (battery 1's names)
        let sets: [&[(&str, f64)]; 3] = [
            &[],
            &[("LOW_VOLT", 11.1), ("CRT_MAH", 400.0), ("FS_LOW_ACT", 2.0), ("MONITOR", 4.0)],
            &[("CAPACITY", 5000.0), ("LOW_TIMER", 0.3), ("FS_CRT_ACT", 5.0), ("FS_VOLTSRC", 1.0)],
        ];
        for (k, set) in sets.iter().enumerate() {
            let get = |field: &str| set.iter().find(|(n, _)| *n == field).map(|(_, v)| *v);
            let s = Settings::from_params(v, get).unwrap();
            out.push(format!(
                "settings {} {k} {} {} {} {} {} {} {} {} {} {}",
                v.name(),
                bits(Some(s.capacity_mah)),
                bits(Some(s.low_volt)),
                bits(Some(s.low_timer_s)),
                bits(Some(s.low_mah)),
                bits(Some(s.crt_volt)),
                bits(Some(s.crt_mah)),
                s.low_action,
                s.crt_action,
                s.volt_source,
                s.monitor.map_or("-".to_string(), |m| m.to_string())
            ));
        }
        let half = |field: &str| (field == "FS_LOW_ACT").then_some(1.5);
        assert_eq!(Settings::from_params(v, half), Err("FS_LOW_ACT"));
        for critical in [false, true] {
            for code in -1..=7 {
                let name = v.action_name(critical, code).unwrap_or("-");
                if let Some(action) = v.action(critical, code) {
                    assert_eq!(v.code(critical, action), Some(code));
                }
                out.push(format!(
                    "action {} {} {} {}|{}",
                    v.name(),
                    u8::from(critical),
                    code,
                    v.priority(code),
                    name
                ));
            }
        }
        for code in -1..=7 {
            for mask in 0..32u8 {
                let s = Situation {
                    home_set: mask & 1 != 0,
                    position_fix: mask & 2 != 0,
                    smart_rtl_ready: mask & 4 != 0,
                    quadplane: mask & 8 != 0,
                    landing_sequence: mask & 16 != 0,
                };
                let outcome = v.resolve(code, &s).name();
                out.push(format!("resolve {} {} {} {}", v.name(), code, mask, outcome));
            }
        }
    }
    for i in 0..=17u8 {
        let prefix = battery_prefix(i).unwrap_or("-");
        out.push(format!("prefix {i} {prefix}"));
        if let Some(p) = battery_prefix(i) {
            assert_eq!(split_battery_name(&format!("{p}LOW_VOLT")), Some((i, "LOW_VOLT")));
        }
    }
    assert_eq!(split_battery_name("BATTH_LOW_VOLT"), None);
    assert_eq!(split_battery_name("BATT_"), None);
    for line in out {
        println!("{line}");
    }
}
