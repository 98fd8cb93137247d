//! MAVLink from the network, both ways: the bytes a vehicle sends the ground station
//! (`link`), and the bytes a ground station sends `aviary vehicles` (`vehicles`).

use std::sync::LazyLock;

use aviary_diagnostics::FileId;
use aviary_mavlink::mavlink::dialects::ardupilotmega::MavMessage;
use aviary_mavlink::mavlink::MavlinkReader;
use aviary_mavlink::Origin;
use aviary_world::World;

/// Read once per process: AFL runs many inputs in one (persistent mode).
fn example_world() -> &'static World {
    static WORLD: LazyLock<World> = LazyLock::new(|| {
        let (world, diagnostics) = aviary_world::parse_world(FileId(0), crate::EXAMPLE_WORLD);
        assert!(diagnostics.is_empty(), "the example world has problems");
        world.expect("the example world")
    });
    &WORLD
}

fn origin(world: &World) -> Origin {
    let o = world.site.origin.as_ref().expect("the example world has an origin");
    Origin { lat: o.lat, lon: o.lon, alt: o.alt }
}

/// The bytes as a vehicle's (system 1) on a link of the example world, looking for its
/// targets with a 40 m sensor. Whatever came, what is believed is a place, a charge, a
/// distance and a time a drone could have.
pub fn link(data: &[u8]) {
    let heard = heard_on_a_link(data);
    if let Some(fix) = heard.fix {
        assert!(fix.pos.iter().all(|v| v.is_finite()), "a position of {:?}", fix.pos);
        assert!(fix.speed.is_finite() && fix.heading.is_finite() && fix.home_amsl.is_finite());
    }
    if let Some(charge) = heard.battery {
        assert!((0.0..=1.0).contains(&charge), "a charge of {charge}");
    }
    assert!(heard.odometer.is_finite() && heard.odometer >= 0.0, "{heard:?}");
    assert!(heard.flight_time.is_finite() && heard.flight_time >= 0.0, "{heard:?}");
}

/// What the ground station believes of system 1 after `data` came on a link of the
/// example world, looking for its targets with a 40 m sensor.
pub fn heard_on_a_link(data: &[u8]) -> aviary_mavlink::receive::Heard {
    let world = example_world();
    aviary_mavlink::receive::hear(data, origin(world), world.targets.clone(), 40.0)
}

/// What the example world's `aviary vehicles` answers to `data` from a ground station
/// (booted and ready to arm at once, so commands take effect), over 10 s of flight.
pub fn answers_of_the_vehicles(data: &[u8]) -> Vec<Vec<u8>> {
    answers_as(data, aviary_vehicles::Flavour::ArduPilot)
}

/// The same of `aviary vehicles --autopilot px4`.
pub fn answers_of_px4_vehicles(data: &[u8]) -> Vec<Vec<u8>> {
    answers_as(data, aviary_vehicles::Flavour::Px4)
}

fn answers_as(data: &[u8], autopilot: aviary_vehicles::Flavour) -> Vec<Vec<u8>> {
    let world = example_world();
    let runtime =
        tokio::runtime::Builder::new_current_thread().enable_all().build().expect("a runtime");
    runtime.block_on(aviary_vehicles::answer(
        world,
        aviary_vehicles::Behaviour { boot_time: 0.0, prearm_time: 0.0, autopilot },
        data,
        10.0,
    ))
}

/// The bytes as a ground station's to the example world's `aviary vehicles` (booted and
/// ready to arm at once), then 10 s of flight, as ArduCopter and as PX4. Every answer is
/// a whole MAVLink 2 frame from one of the world's vehicles.
pub fn vehicles(data: &[u8]) {
    let systems: Vec<u32> = (1..=example_world().drones.len() as u32).collect();
    let mut answers = answers_of_the_vehicles(data);
    answers.extend(answers_of_px4_vehicles(data));
    for frame in answers {
        let mut reader = MavlinkReader::new(frame.as_slice());
        let raw = reader
            .read_any_raw_message::<MavMessage>()
            .unwrap_or_else(|e| panic!("an answer that is not a frame ({e}): {frame:02x?}"));
        assert!(systems.contains(&raw.system_id()), "an answer from system {}", raw.system_id());
    }
}
