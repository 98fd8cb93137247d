//! Every seed, and every crash AFL has found and that was fixed (`regressions/`), runs
//! through the targets without AFL: `cargo test` in `fuzz/`.

use std::path::Path;

fn each_file(dir: &str, run: fn(&[u8])) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return 0;
    };
    let mut n = 0;
    for entry in entries {
        let path = entry.expect("a directory entry").path();
        if path.is_file() {
            run(&std::fs::read(&path).expect("a readable file"));
            n += 1;
        }
    }
    n
}

#[test]
fn seeds_and_regressions_of_fuzz_mission() {
    assert!(each_file("in/mission", aviary_fuzz::mission) > 0);
    each_file("regressions/mission", aviary_fuzz::mission);
}

#[test]
fn seeds_and_regressions_of_fuzz_world() {
    assert!(each_file("in/world", aviary_fuzz::world) > 0);
    each_file("regressions/world", aviary_fuzz::world);
}

#[test]
fn seeds_and_regressions_of_fuzz_operator() {
    assert!(each_file("in/operator", aviary_fuzz::operator) > 0);
    each_file("regressions/operator", aviary_fuzz::operator);
}

#[test]
fn seeds_and_regressions_of_fuzz_lsp() {
    assert!(each_file("in/lsp", aviary_fuzz::lsp) > 0);
    each_file("regressions/lsp", aviary_fuzz::lsp);
}

#[test]
fn seeds_and_regressions_of_fuzz_link() {
    assert!(each_file("in/link", aviary_fuzz::link) > 0);
    each_file("regressions/link", aviary_fuzz::link);
}

#[test]
fn seeds_and_regressions_of_fuzz_vehicles() {
    assert!(each_file("in/vehicles", aviary_fuzz::vehicles) > 0);
    each_file("regressions/vehicles", aviary_fuzz::vehicles);
}

/// The MAVLink seeds are worth starting from only if they reach past the framing: the
/// telemetry seed gives a fix, a charge, a detection and the battery failsafe's exception;
/// the implausible one an alarm; the
/// ground station's session arms drone 1 and flies it.
#[test]
fn the_mavlink_seeds_reach_past_the_framing() {
    let read = |name: &str| {
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join(name)).expect("a seed")
    };
    let flight = aviary_fuzz::heard_on_a_link(&read("in/link/flight_over_a_target.bin"));
    assert!(flight.fix.is_some() && flight.battery.is_some(), "{flight:?}");
    assert!(flight.events > 0, "{flight:?}");
    assert!(
        flight.alarms.iter().any(|a| a.exception == aviary_api::BuiltinException::BatteryCritical),
        "{flight:?}"
    );
    let jumps = aviary_fuzz::heard_on_a_link(&read("in/link/implausible.bin"));
    assert!(!jumps.alarms.is_empty(), "{jumps:?}");

    use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavMessage, MavModeFlag};
    let answers = aviary_fuzz::answers_of_the_vehicles(&read("in/vehicles/session.bin"));
    let messages: Vec<(u32, MavMessage)> = answers
        .iter()
        .map(|f| {
            let mut reader = aviary_mavlink::mavlink::MavlinkReader::new(f.as_slice());
            let (header, m) = reader.read_any_message::<MavMessage>().expect("a frame");
            (header.system_id, m)
        })
        .collect();
    let armed = messages.iter().any(|(s, m)| {
        *s == 1 && matches!(m, MavMessage::HEARTBEAT(h) if h.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED))
    });
    let climbed = messages.iter().any(|(s, m)| {
        *s == 1 && matches!(m, MavMessage::GLOBAL_POSITION_INT(p) if p.relative_alt > 5_000)
    });
    assert!(armed && climbed, "drone 1 did not arm and climb: {} answers", answers.len());
}

#[test]
fn seeds_and_regressions_of_fuzz_station() {
    assert!(each_file("in/station", aviary_fuzz::station) > 0);
    each_file("regressions/station", aviary_fuzz::station);
}
