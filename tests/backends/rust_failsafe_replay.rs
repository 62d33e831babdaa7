//! The failsafe replay: the streams Python's failsafe evaluator is tested on, written by the Python side
//! (tests/rust_failsafe_cases.py) as lines, fed sample by sample to `battgen::failsafe::Failsafe`; each
//! event must print as the line Python's evaluator gave. The data file is `tests/failsafe_streams.txt`,
//! or the one `BATTGEN_FAILSAFE_STREAMS` names.

use battgen::failsafe::{Event, Failsafe, Reading, Sample, Settings, Situation, Variants, Vehicle};

fn float(word: &str) -> Option<f64> {
    if word == "-" {
        return None;
    }
    Some(f64::from_bits(u64::from_str_radix(word, 16).expect("hex bits")))
}

fn bits(value: f64) -> String {
    format!("{:016x}", value.to_bits())
}

fn flag(word: &str) -> bool {
    word == "1"
}

fn line(e: &Event, vehicle: Vehicle) -> String {
    let name = match e.action_name(vehicle) {
        Some(name) => name.to_string(),
        None => format!("unknown ({})", e.action_code),
    };
    format!(
        "event {} {} {} {} {} {} {} {} {} {} {} {} {}|{}|{}",
        e.time_ms,
        e.battery,
        e.level.name(),
        e.cause.name(),
        e.action_code,
        u8::from(e.executed),
        e.outcome.name().replace(' ', "_"),
        e.priority,
        bits(e.value),
        bits(e.threshold),
        bits(e.voltage),
        bits(e.consumed_mah),
        if e.resting_voltage { "resting" } else { "raw" },
        name,
        e.ardupilot_text()
    )
}

#[test]
fn failsafe_streams_give_pythons_events() {
    let path = std::env::var("BATTGEN_FAILSAFE_STREAMS").unwrap_or_else(|_| {
        concat!(env!("CARGO_MANIFEST_DIR"), "/tests/failsafe_streams.txt").to_string()
    });
    let text = std::fs::read_to_string(&path).expect("the failsafe streams");
    let (mut cases, mut events) = (0, 0);
    let mut state: Option<(Failsafe, Vec<String>, Vec<String>)> = None;
    for (number, row) in text.lines().enumerate() {
        let (head, words) = match row.split_once(' ') {
            Some((head, rest)) => (head, rest.split(' ').collect::<Vec<_>>()),
            None => (row, Vec::new()),
        };
        match head {
            "case" => {
                let vehicle = Vehicle::from_name(words[0]).expect("a vehicle");
                let variants = Variants {
                    seed_critical: flag(words[1]),
                    distance: flag(words[2]),
                };
                let mut fs = Failsafe::new(vehicle, variants);
                fs.situation = Situation {
                    home_set: flag(words[3]),
                    position_fix: flag(words[4]),
                    smart_rtl_ready: flag(words[5]),
                    quadplane: flag(words[6]),
                    landing_sequence: flag(words[7]),
                };
                state = Some((fs, Vec::new(), Vec::new()));
            }
            "settings" => {
                let (fs, _, _) = state.as_mut().expect("a case");
                let s = Settings {
                    capacity_mah: float(words[1]).unwrap(),
                    low_volt: float(words[2]).unwrap(),
                    low_timer_s: float(words[3]).unwrap(),
                    low_mah: float(words[4]).unwrap(),
                    crt_volt: float(words[5]).unwrap(),
                    crt_mah: float(words[6]).unwrap(),
                    low_action: words[7].parse().unwrap(),
                    crt_action: words[8].parse().unwrap(),
                    volt_source: words[9].parse().unwrap(),
                    monitor: words[10].parse().ok(),
                };
                fs.configure(words[0].parse().unwrap(), s).unwrap();
            }
            "sample" => {
                let (fs, _, got) = state.as_mut().expect("a case");
                let sample = Sample {
                    reading: Reading {
                        voltage_v: float(words[3]),
                        current_a: float(words[4]),
                        consumed_mah: float(words[5]),
                        remaining_mah: None,
                    },
                    armed: flag(words[2]),
                    distance_to_home_m: float(words[6]),
                    ..Sample::default()
                };
                let now: u32 = words[0].parse().unwrap();
                let vehicle = fs.vehicle();
                if let Some(e) = fs.update(now, words[1].parse().unwrap(), &sample).unwrap() {
                    got.push(line(&e, vehicle));
                }
            }
            "event" => state.as_mut().expect("a case").1.push(row.to_string()),
            "end" => {
                let (_, expected, got) = state.take().expect("a case");
                assert_eq!(got, expected, "case ending on line {}", number + 1);
                cases += 1;
                events += expected.len();
            }
            _ => panic!("line {}: unexpected {:?}", number + 1, row),
        }
    }
    assert!(state.is_none(), "the last case has no end");
    assert!(cases > 0, "no case in {path}");
    println!("failsafe replay: {cases} streams, {events} events");
}
