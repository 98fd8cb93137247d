use aviary_diagnostics::{Code, Diagnostic, FileId};

use crate::node::{Node, Value};
use crate::*;

const EXAMPLE: &str = include_str!("../../../examples/search_and_rescue.world.toml");

fn parse(text: &str) -> (Option<World>, Vec<Diagnostic>) {
    parse_world(FileId(7), text)
}

fn ok(text: &str) -> World {
    let (world, diags) = parse(text);
    assert!(diags.is_empty(), "unexpected diagnostics: {diags:#?}");
    world.expect("a world when there are no diagnostics")
}

/// (message, the text the span covers, help) of every diagnostic.
fn errors(text: &str) -> Vec<(String, String, String)> {
    let (world, diags) = parse(text);
    assert!(world.is_none(), "errors must mean no world");
    assert!(!diags.is_empty());
    diags
        .iter()
        .map(|d| {
            assert_eq!(d.code, Code::WorldFile);
            assert_eq!(d.primary.file, FileId(7));
            let help = d.help.clone().expect("every diagnostic says what to write instead");
            (d.message.clone(), text[d.primary.span.range()].to_owned(), help)
        })
        .collect()
}

/// The one diagnostic of `text`: (message, spanned text, help).
fn error(text: &str) -> (String, String, String) {
    let mut all = errors(text);
    assert_eq!(all.len(), 1, "expected one diagnostic, got {all:#?}");
    all.remove(0)
}

const HOME: &str = "[drones.d]\nhome = [0, 0]\n";

#[test]
fn example_world() {
    let w = ok(EXAMPLE);
    let drones: Vec<&str> = w.drones.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(
        drones,
        [
            "video_drone1",
            "video_drone2",
            "flir_drone1",
            "flir_drone2",
            "sensor_drone",
            "beacon_drone1",
            "beacon_drone2"
        ]
    );
    let groups: Vec<(&str, Vec<&str>)> = w
        .groups
        .iter()
        .map(|g| (g.name.as_str(), g.members.iter().map(|&m| w.drones[m].name.as_str()).collect()))
        .collect();
    assert_eq!(
        groups,
        [
            ("video", vec!["video_drone1", "video_drone2"]),
            ("flir", vec!["flir_drone1", "flir_drone2"]),
            ("sensor", vec!["sensor_drone"]),
            ("beacon", vec!["beacon_drone1", "beacon_drone2"]),
        ]
    );
    let a = w.place("BuildingA").unwrap();
    assert_eq!((a.at, a.has_z), ([150.0, 100.0, 0.0], false));
    assert_eq!(&EXAMPLE[a.span.range()], "BuildingA");
    assert_eq!(w.area("Area1").unwrap().centroid(), [200.0, 325.0]);
    assert_eq!(w.site.name.as_deref(), Some("Crash site"));
    assert_eq!(w.site.origin, Some(Geo { lat: 46.6167, lon: 14.2650, alt: 440.0 }));
    assert_eq!(w.site.max_altitude, Some(120.0));
    assert_eq!(w.site.min_separation, 5.0);
    assert_eq!(w.site.geofence.as_ref().map(Vec::len), Some(4));
    let d = w.drone("flir_drone2").unwrap();
    assert_eq!(d.home, [5.0, 5.0, 0.0]);
    assert_eq!(*d.sensors, ["thermal"]);
    assert_eq!((d.max_speed, d.climb_rate, d.acceleration), (10.0, 3.0, 3.0));
    assert_eq!((d.battery, d.endurance, &d.backend), (100.0, 1800.0, &Backend::Sim));
    assert_eq!(&EXAMPLE[d.span.range()], "flir_drone2");
    assert_eq!(*w.drone("beacon_drone2").unwrap().payload, ["Body"]);
    assert_eq!(w.sensor("thermal").unwrap().detects, ["Body"]);
    assert_eq!(w.sensor("radiation").unwrap().range, 25.0);
    assert_eq!(w.targets[2], Target { kind: "Radiation".into(), at: [260.0, -300.0, 0.0] });
    assert!(w.faults.is_empty());
    assert_eq!(w.group("video").unwrap().members.len(), 2);
    assert_eq!(w.names().count(), 7 + 4 + 6 + 3);
    assert!(w.names().any(|n| n == "RadiationZone"));
}

#[test]
fn every_key_and_value_of_the_example_has_its_own_span() {
    fn walk(node: &Node, text: &str) {
        match &node.value {
            Value::Table(entries) => {
                for e in entries {
                    assert_eq!(&text[e.key_span.range()], e.key);
                    walk(&e.node, text);
                }
            }
            Value::Array(items) => {
                assert!(text[node.span.range()].starts_with('['));
                items.iter().for_each(|n| walk(n, text));
            }
            Value::Int(i) => assert_eq!(text[node.span.range()].parse::<i64>().unwrap(), *i),
            _ => assert!(!node.span.range().is_empty()),
        }
    }
    walk(&Node::parse_serde(EXAMPLE).unwrap(), EXAMPLE);
}

#[test]
fn empty_text_is_the_empty_world() {
    assert_eq!(ok(""), World::default());
    assert_eq!(ok("# nothing here\n\n"), World::default());
    assert_eq!(ok("").site.min_separation, 5.0);
    assert_eq!(ok("").site.link_loss_rtl_after, 10.0);
    assert_eq!(ok("").site.separation_timeout, 30.0);
}

#[test]
fn separation_timeout_is_positive_seconds() {
    assert_eq!(ok("[site]\nseparation_timeout = 12.5\n").site.separation_timeout, 12.5);
    assert_eq!(ok("[site]\nseparation_timeout = 60\n").site.separation_timeout, 60.0);
    for bad in ["0", "-1"] {
        let (msg, at, help) = error(&format!("[site]\nseparation_timeout = {bad}\n"));
        assert_eq!(msg, format!("`separation_timeout` must be greater than zero, found {bad}"));
        assert_eq!(at, bad);
        assert_eq!(help, "write a positive number");
    }
    let (msg, _, _) = error("[site]\nseparation_timeout = \"long\"\n");
    assert!(msg.starts_with("`separation_timeout` must be a number"), "{msg}");
    let (_, _, help) = error("[site]\nseparation_time = 3\n");
    assert!(help.contains("separation_timeout"), "{help}");
}

#[test]
fn link_loss_rtl_after_is_positive_seconds() {
    let w = ok("[site]\nlink_loss_rtl_after = 4.5\n");
    assert_eq!(w.site.link_loss_rtl_after, 4.5);
    assert_eq!(ok("[site]\nlink_loss_rtl_after = 30\n").site.link_loss_rtl_after, 30.0);
    for bad in ["0", "-2"] {
        let (msg, at, help) = error(&format!("[site]\nlink_loss_rtl_after = {bad}\n"));
        assert_eq!(msg, format!("`link_loss_rtl_after` must be greater than zero, found {bad}"));
        assert_eq!(at, bad);
        assert_eq!(help, "write a positive number");
    }
    let (msg, _, _) = error("[site]\nlink_loss_rtl_after = \"soon\"\n");
    assert!(msg.starts_with("`link_loss_rtl_after` must be a number"), "{msg}");
    let (_, _, help) = error("[site]\nlink_loss_rtl = 3\n");
    assert!(help.contains("link_loss_rtl_after"), "{help}");
}

#[test]
fn other_forms_and_defaults() {
    let w = ok("drones.a = { home = [1, 2, 3], max_speed = 4, battery = 50 }\n\
         [site]\nmin_separation = 0\n[places]\nTop = [1, 2, 30]\n[areas]\nT = [[0, 0], [3, 0], [0, 3]]\n");
    let a = w.drone("a").unwrap();
    assert_eq!((a.home, a.max_speed, a.battery), ([1.0, 2.0, 3.0], 4.0, 50.0));
    assert!(w.place("Top").unwrap().has_z);
    assert_eq!(w.area("T").unwrap().centroid(), [1.0, 1.0]);
    assert_eq!(w.site.min_separation, 0.0);
}

#[test]
fn centroid_of_degenerate_polygons_is_the_mean_of_corners() {
    let line = Area {
        name: "L".into(),
        polygon: vec![[0.0, 0.0], [2.0, 0.0], [4.0, 0.0]],
        span: Default::default(),
    };
    assert_eq!(line.centroid(), [2.0, 0.0]);
    let point = Area { name: "P".into(), polygon: vec![[1.0, 1.0]; 3], span: Default::default() };
    assert_eq!(point.centroid(), [1.0, 1.0]);
    let square = Area {
        name: "S".into(),
        polygon: vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]],
        span: Default::default(),
    };
    assert!(square.contains([1.0, 1.0]) && !square.contains([3.0, 1.0]));
}

#[test]
fn attributes_and_mavlink() {
    let w = ok("[drones.a]\nhome = [0, 0]\ncolour = \"red\"\nweight = 2.5\nlights = true\n\
         tags = [\"x\", 1]\nmavlink = \"udp:127.0.0.1:14550\"\nsystem_id = 3\n");
    let a = w.drone("a").unwrap();
    assert_eq!(a.attribute("colour"), Some(&AttributeValue::Text("red".into())));
    assert_eq!(a.attribute("weight"), Some(&AttributeValue::Number(2.5)));
    assert_eq!(a.attribute("lights"), Some(&AttributeValue::Bool(true)));
    assert_eq!(a.attribute("tags"), Some(&AttributeValue::Other("[\"x\", 1]".into())));
    assert_eq!(a.attributes.len(), 4);
    assert_eq!(
        a.backend,
        Backend::Mavlink(Box::new(Mavlink {
            address: "udp:127.0.0.1:14550".into(),
            system_id: Some(3),
            signing_key: None
        }))
    );
    let w = ok("[drones.c]\nhome = [0, 0]\nsince = 1979-05-27T07:32:00Z\n");
    let since = w.drones[0].attribute("since");
    assert_eq!(since, Some(&AttributeValue::Other("1979-05-27T07:32:00Z".into())));
    let w =
        ok("[drones.b]\nhome = [0, 0]\nbackend = \"mavlink\"\nmavlink = \"tcp:10.0.0.2:5760\"\n");
    assert!(matches!(w.drones[0].backend, Backend::Mavlink(_)));
}

#[test]
fn faults_that_are_right() {
    let w = ok(&format!(
        "{HOME}[[faults]]\ndrone = \"d\"\nat = 30\nkind = \"link_loss\"\nduration = 5\n\
         [[faults]]\ndrone = \"d\"\nat = 60.5\nkind = \"crash\"\n"
    ));
    assert_eq!(w.faults.len(), 2);
    assert_eq!((w.faults[0].kind, w.faults[0].duration), (FaultKind::LinkLoss, Some(5.0)));
    assert_eq!((w.faults[1].kind, w.faults[1].at), (FaultKind::Crash, 60.5));
}

#[test]
fn syntax_errors() {
    let (msg, at, _) = error("[site]\nname = \"x\nmax_altitude = 3\n");
    assert!(msg.starts_with("the world file is not valid TOML"), "{msg}");
    assert!(!msg.contains('\n'));
    assert!(at.is_empty() || "\"x\n".contains(&at), "{at:?}");
    let (msg, at, help) = error("[places]\nA = [1, 2]\nA = [3, 4]\n");
    assert!(msg.contains("duplicate key `A`"), "{msg}");
    assert_eq!(at, "A");
    assert!(help.contains("once"));
}

#[test]
fn wrong_types() {
    let (msg, at, help) = error("[drones.d]\nhome = \"x\"\n");
    assert_eq!(msg, "`home` of drone `d` must be a position [x, y] or [x, y, z], found a string");
    assert_eq!(at, "\"x\"");
    assert!(help.contains("[x, y]"));
    let (msg, at, _) = error(&format!("{HOME}group = 3\n"));
    assert_eq!(msg, "`group` of drone `d` must be a string, found an integer");
    assert_eq!(at, "3");
    let (msg, at, _) = error(&format!("{HOME}sensors = [\"camera\", true]\n"));
    assert_eq!(msg, "`sensors` of drone `d` must hold strings, found a boolean");
    assert_eq!(at, "true");
    let (msg, at, _) = error("site = 3\n");
    assert_eq!(msg, "`site` must be a table, found an integer");
    assert_eq!(at, "3");
    let (msg, at, _) = error("[site]\nmax_altitude = \"high\"\n");
    assert_eq!(msg, "`max_altitude` must be a number, found a string");
    assert_eq!(at, "\"high\"");
}

#[test]
fn places_must_be_two_or_three_numbers() {
    let (msg, at, _) = error("[places]\nA = [1, 2, 3, 4]\n");
    assert_eq!(msg, "place `A` must be 2 or 3 numbers, found 4 numbers");
    assert_eq!(at, "[1, 2, 3, 4]");
    let (msg, at, _) = error("[places]\nA = [1]\n");
    assert_eq!(msg, "place `A` must be 2 or 3 numbers, found 1 number");
    assert_eq!(at, "[1]");
    let (msg, at, _) = error("[places]\nA = [1, \"b\"]\n");
    assert_eq!(msg, "place `A` must be a number, found a string");
    assert_eq!(at, "\"b\"");
}

#[test]
fn areas_need_three_points() {
    let (msg, at, help) = error("[areas]\nZ = [[0, 0], [1, 1]]\n");
    assert_eq!(msg, "area `Z` has 2 points; a polygon needs at least 3");
    assert_eq!(at, "[[0, 0], [1, 1]]");
    assert!(help.contains("at least three"));
    let (msg, at, _) = error("[areas]\nZ = [[0, 0], [1, 1], [2]]\n");
    assert_eq!(msg, "a corner of area `Z` must be 2 numbers [x, y], found 1 number");
    assert_eq!(at, "[2]");
    let (msg, at, _) = error("[site]\ngeofence = [[0, 0], [1, 0]]\n");
    assert_eq!(msg, "the geofence has 2 points; a polygon needs at least 3");
    assert_eq!(at, "[[0, 0], [1, 0]]");
}

#[test]
fn drone_without_home() {
    let (msg, at, help) = error("[drones.lonely]\ngroup = \"g\"\n");
    assert_eq!(msg, "drone `lonely` has no `home`");
    assert_eq!(at, "lonely");
    assert!(help.starts_with("add `home = [x, y]`"));
}

#[test]
fn undefined_sensor() {
    let text = "[sensors.thermal]\ndetects = [\"Body\"]\nrange = 20\n[drones.d]\nhome = [0, 0]\nsensors = [\"thermel\", \"lidar\"]\n";
    let all = errors(text);
    assert_eq!(all.len(), 2);
    assert_eq!(all[0].0, "drone `d` has sensor `thermel`, but no `[sensors.thermel]` defines it");
    assert_eq!(all[0].1, "\"thermel\"");
    assert_eq!(all[0].2, "did you mean `thermal`?");
    assert_eq!(all[1].1, "\"lidar\"");
    assert!(all[1].2.contains("`thermal`, `camera`"), "{}", all[1].2);
    // The camera is built in.
    ok(&format!("{HOME}sensors = [\"camera\"]\n"));
}

#[test]
fn sensor_problems() {
    let (msg, at, _) = error("[sensors.sonar]\ndetects = [\"Body\"]\n");
    assert_eq!(msg, "sensor `sonar` has no `range`");
    assert_eq!(at, "sonar");
    let (msg, at, _) = error("[sensors.sonar]\nrange = 5\n");
    assert_eq!(msg, "sensor `sonar` has no `detects`");
    assert_eq!(at, "sonar");
    let (msg, at, _) = error("[sensors.sonar]\ndetects = []\nrange = 0\n");
    assert_eq!(msg, "`range` of sensor `sonar` must be greater than zero, found 0");
    assert_eq!(at, "0");
}

/// What the simulator may draw from the run's seed: a sensor's chance of finding a
/// target, and a fault's time within a range.
#[test]
fn chances_and_ranges_of_time() {
    let w = ok("[sensors.sonar]\ndetects = [\"Body\"]\nrange = 5\nprobability = 0.25\n\
                [sensors.eye]\ndetects = [\"Body\"]\nrange = 5\n");
    assert_eq!((w.sensors[0].probability, w.sensors[1].probability), (0.25, 1.0));
    let sensor =
        |p: &str| error(&format!("[sensors.s]\ndetects = []\nrange = 5\nprobability = {p}\n"));
    assert_eq!(sensor("1.5").0, "`probability` of sensor `s` must be between 0 and 1, found 1.5");
    assert_eq!(
        sensor("\"high\"").0,
        "`probability` of sensor `s` must be a number, found a string"
    );
    ok("[sensors.s]\ndetects = []\nrange = 5\nprobability = 0\n");

    let fault =
        |at: &str| format!("{HOME}[[faults]]\ndrone = \"d\"\nat = {at}\nkind = \"crash\"\n");
    let w = ok(&fault("[30, 90.5]"));
    assert_eq!((w.faults[0].at, w.faults[0].latest), (30.0, Some(90.5)));
    let w = ok(&fault("[30, 30]"));
    assert_eq!((w.faults[0].at, w.faults[0].latest), (30.0, Some(30.0)));
    assert_eq!(ok(&fault("12")).faults[0].latest, None);
    let (msg, at, help) = error(&fault("[90, 30]"));
    assert_eq!(msg, "the range `at` of a fault runs from 90 back to 30");
    assert_eq!(at, "[90, 30]");
    assert_eq!(help, "write the earlier time first, e.g. `at = [30, 90]`");
    assert_eq!(
        error(&fault("[1, 2, 3]")).0,
        "`at` of a fault must be a time or a range [earliest, latest], found 3 numbers"
    );
    let (msg, at, _) = error(&fault("[-1, 2]"));
    assert_eq!(
        (msg.as_str(), at.as_str()),
        ("`at` of a fault must be zero or more seconds, found -1", "-1")
    );
    assert_eq!(error(&fault("[1, \"x\"]")).0, "`at` of a fault must be a number, found a string");
}

#[test]
fn fault_for_an_unknown_drone() {
    let (msg, at, help) =
        error(&format!("{HOME}[[faults]]\ndrone = \"e\"\nat = 1\nkind = \"crash\"\n"));
    assert_eq!(msg, "the fault names drone `e`, which is not in `[drones]`");
    assert_eq!(at, "\"e\"");
    assert_eq!(help, "name one of the drones: `d`");
    let text =
        "[drones.scout]\nhome = [0, 0]\n[[faults]]\ndrone = \"scuot\"\nat = 1\nkind = \"crash\"\n";
    assert_eq!(error(text).2, "did you mean `scout`?");
}

#[test]
fn unknown_fault_kind() {
    let (msg, at, help) =
        error(&format!("{HOME}[[faults]]\ndrone = \"d\"\nat = 1\nkind = \"explode\"\n"));
    assert_eq!(msg, "unknown fault kind `explode`");
    assert_eq!(at, "\"explode\"");
    assert_eq!(
        help,
        "write one of `battery_critical`, `link_loss`, `crash`, `gps_loss`, `motor_failure`"
    );
    let (_, _, help) =
        error(&format!("{HOME}[[faults]]\ndrone = \"d\"\nat = 1\nkind = \"link-loss\"\n"));
    assert!(help.starts_with("did you mean `link_loss`?"));
}

#[test]
fn durations_of_faults() {
    for kind in ["link_loss", "gps_loss"] {
        let text = format!("{HOME}[[faults]]\ndrone = \"d\"\nat = 1\nkind = \"{kind}\"\n");
        let (msg, at, help) = error(&text);
        assert_eq!(msg, format!("a `{kind}` fault needs a `duration`"));
        assert_eq!(at, format!("\"{kind}\""));
        assert!(help.contains("duration = 10"));
    }
    let text = format!("{HOME}[[faults]]\ndrone = \"d\"\nat = 1\nkind = \"crash\"\nduration = 3\n");
    let (msg, at, _) = error(&text);
    assert_eq!(msg, "`duration` applies only to `link_loss` and `gps_loss` faults, not to `crash`");
    assert_eq!(at, "duration");
    let (msg, at, _) =
        error(&format!("{HOME}[[faults]]\ndrone = \"d\"\nat = -1\nkind = \"crash\"\n"));
    assert_eq!(msg, "`at` of a fault must be zero or more seconds, found -1");
    assert_eq!(at, "-1");
    let (msg, at, _) = error(&format!("{HOME}[[faults]]\ndrone = \"d\"\nkind = \"crash\"\n"));
    assert_eq!(msg, "a fault has no `at`");
    assert_eq!(at, "[[faults]]");
}

#[test]
fn speeds_and_endurance_must_be_positive() {
    for key in [
        "max_speed",
        "climb_rate",
        "acceleration",
        "endurance",
        "descent_rate",
        "land_speed",
        "takeoff_speed",
        "return_speed",
        "max_airspeed",
        "battery_capacity",
        "flight_current",
    ] {
        let (msg, at, _) = error(&format!("{HOME}{key} = -2\n"));
        assert_eq!(msg, format!("`{key}` of drone `d` must be greater than zero, found -2"));
        assert_eq!(at, "-2");
    }
    let (msg, at, _) = error(&format!("{HOME}endurance = 0.0\n"));
    assert_eq!(msg, "`endurance` of drone `d` must be greater than zero, found 0");
    assert_eq!(at, "0.0");
}

#[test]
fn heights_and_waits_may_be_zero_but_not_below() {
    for key in ["land_speed_below", "return_altitude", "return_loiter"] {
        let (msg, at, help) = error(&format!("{HOME}{key} = -1\n"));
        assert_eq!(msg, format!("`{key}` of drone `d` must not be below zero, found -1"));
        assert_eq!((at.as_str(), help.as_str()), ("-1", "write zero or a positive number"));
    }
}

#[test]
fn descent_and_landing_follow_the_climb_unless_given() {
    let w = ok(&format!("{HOME}climb_rate = 2\n"));
    let d = &w.drones[0];
    assert_eq!(
        (d.descent_rate, d.land_speed, d.land_speed_below, d.return_altitude, d.return_loiter),
        (2.0, 2.0, 10.0, 10.0, 0.0)
    );
    let w = ok(&format!("{HOME}climb_rate = 2.5\ndescent_rate = 1.5\nland_speed = 0.5\nreturn_altitude = 15\nreturn_loiter = 5\n"));
    let d = &w.drones[0];
    assert_eq!(
        (d.descent_rate, d.land_speed, d.return_altitude, d.return_loiter),
        (1.5, 0.5, 15.0, 5.0)
    );
    assert!(d.attributes.is_empty(), "figures are not attributes");
}

#[test]
fn the_take_off_and_the_way_home_follow_the_climb_and_the_speed_unless_given() {
    let w = ok(&format!(
        "{HOME}climb_rate = 2
max_speed = 12
"
    ));
    let d = &w.drones[0];
    assert_eq!((d.takeoff_speed, d.return_speed), (2.0, 12.0));
    assert_eq!(d.fastest(), 14.0);
    // PX4's figures: half the climb rate up from the ground, its cruise speed home.
    let w = ok(&format!(
        "{HOME}climb_rate = 3
takeoff_speed = 1.5
return_speed = 5
"
    ));
    let d = &w.drones[0];
    assert_eq!((d.takeoff_speed, d.return_speed), (1.5, 5.0));
    assert!(d.attributes.is_empty(), "figures are not attributes");
    // A way home faster than the mission may fly still bounds what the drone can do.
    let w = ok(&format!(
        "{HOME}max_speed = 8
return_speed = 11
"
    ));
    assert_eq!(w.drones[0].fastest(), 14.0);
}

#[test]
fn capacity_and_draw_give_the_endurance() {
    let w = ok(&format!("{HOME}endurance = 1800\nbattery_capacity = 3300\nflight_current = 30\n"));
    assert!((w.drones[0].endurance - 396.0).abs() < 1e-9);
    // One of the two alone leaves the endurance as it is.
    let w = ok(&format!("{HOME}battery_capacity = 3300\n"));
    assert_eq!((w.drones[0].endurance, w.drones[0].battery_capacity), (1800.0, Some(3300.0)));
}

#[test]
fn battery_in_percent() {
    let (msg, at, help) = error(&format!("{HOME}battery = 150\n"));
    assert_eq!(msg, "`battery` of drone `d` must be between 0 and 100, found 150");
    assert_eq!(at, "150");
    assert_eq!(help, "write a number from 0 to 100");
    ok(&format!("{HOME}battery = 0\n"));
    ok(&format!("{HOME}battery = 100\n"));
}

#[test]
fn unknown_tables_and_keys() {
    let (msg, at, help) = error("[drone.a]\nhome = [0, 0]\n");
    assert_eq!(msg, "unknown table `[drone]` in the world file");
    assert_eq!(at, "drone");
    assert!(help.starts_with("did you mean `[drones]`?"), "{help}");
    let (msg, at, _) = error("speed = 3\n");
    assert_eq!(msg, "unknown key `speed` at the top of the world file");
    assert_eq!(at, "speed");
    let (msg, at, help) = error("[site]\nmax_alt = 100\n");
    assert_eq!(msg, "unknown key `max_alt` in [site]");
    assert_eq!(at, "max_alt");
    assert!(
        help.contains("`name`, `origin`, `geofence`, `max_altitude`, `min_separation`"),
        "{help}"
    );
    let (msg, at, help) = error("[sensors.s]\ndetects = []\nrange = 3\nrnage = 4\n");
    assert_eq!(msg, "unknown key `rnage` in [sensors.s]");
    assert_eq!(at, "rnage");
    assert!(help.starts_with("did you mean `range`?"));
    let (msg, at, help) = error("[[targets]]\nkind = \"Body\"\nat = [1, 2]\nsize = 3\n");
    assert_eq!(msg, "unknown key `size` in [[targets]]");
    assert_eq!(at, "size");
    assert_eq!(help, "remove it; the known keys are `kind`, `at`");
    let text = format!("{HOME}[[faults]]\ndrone = \"d\"\nat = 1\nkind = \"crash\"\nwhen = 3\n");
    let (msg, at, help) = error(&text);
    assert_eq!(msg, "unknown key `when` in [[faults]]");
    assert_eq!(at, "when");
    assert!(help.contains("`drone`, `at`, `kind`, `duration`"));
    let (msg, at, _) = error("[site]\norigin = { lat = 1, lon = 2, height = 3 }\n");
    assert_eq!(msg, "unknown key `height` in `origin`");
    assert_eq!(at, "height");
}

#[test]
fn one_name_one_meaning() {
    let (msg, at, help) = error("[places]\nX = [0, 0]\n[drones.X]\nhome = [0, 0]\n");
    assert_eq!(
        msg,
        "the name `X` is used for a place and for a drone, so mission code could not tell which is meant"
    );
    assert_eq!(at, "X");
    assert!(help.starts_with("rename one of them"));
    let (world, diags) = parse("[places]\nX = [0, 0]\n[drones.X]\nhome = [0, 0]\n");
    assert!(world.is_none());
    assert_eq!(diags[0].primary.span.start, 28);
    assert_eq!(diags[0].secondary[0].span.start, 9);
    let (msg, at, _) = error("[drones.a]\nhome = [0, 0]\ngroup = \"a\"\n");
    assert_eq!(
        msg,
        "the name `a` is used for a drone and for a group, so mission code could not tell which is meant"
    );
    assert_eq!(at, "\"a\"");
    let (msg, _, _) = error("[areas]\nZ = [[0, 0], [1, 0], [0, 1]]\n[places]\nZ = [1, 1]\n");
    assert!(msg.contains("for an area and for a place"));
}

#[test]
fn names_must_be_identifiers() {
    let (msg, at, help) = error("[places]\n\"my-place\" = [0, 0]\n");
    assert_eq!(msg, "place `my-place` is not a valid name, so mission code could not refer to it");
    assert_eq!(at, "\"my-place\"");
    assert_eq!(help, "use letters, digits and `_`, not starting with a digit, e.g. `my_place`");
    let (msg, at, _) = error("[drones.2fast]\nhome = [0, 0]\n");
    assert_eq!(msg, "drone `2fast` is not a valid name, so mission code could not refer to it");
    assert_eq!(at, "2fast");
    let (msg, at, _) = error(&format!("{HOME}group = \"red team\"\n"));
    assert_eq!(msg, "group `red team` is not a valid name, so mission code could not refer to it");
    assert_eq!(at, "\"red team\"");
    let (msg, _, _) = error("[areas]\n\"\" = [[0, 0], [1, 0], [0, 1]]\n");
    assert_eq!(msg, "area `` is not a valid name, so mission code could not refer to it");
}

#[test]
fn backend_problems() {
    let (msg, at, _) = error(&format!("{HOME}mavlink = \"carrier-pigeon\"\n"));
    assert_eq!(
        msg,
        "the `mavlink` address `carrier-pigeon` of drone `d` is not `SCHEME:HOST:PORT`"
    );
    assert_eq!(at, "\"carrier-pigeon\"");
    let (msg, _, _) = error(&format!("{HOME}mavlink = \"udp:127.0.0.1:99999\"\n"));
    assert_eq!(
        msg,
        "the `mavlink` address `udp:127.0.0.1:99999` of drone `d` has `99999` where the port number (0 to 65535) belongs"
    );
    let (msg, at, _) = error(&format!("{HOME}mavlink = \"agent:field/1\"\n"));
    assert_eq!(
        msg,
        "the `mavlink` address `agent:field/1` of drone `d`: an agent's name holds only letters, digits, `-`, `_` and `.`, and `field/1` holds `/`"
    );
    assert_eq!(at, "\"agent:field/1\"");
    let (msg, _, _) = error(&format!("{HOME}mavlink = \"agent:\"\n"));
    assert_eq!(msg, "the `mavlink` address `agent:` of drone `d`: an agent's name is empty");
    let (msg, at, _) = error(&format!("{HOME}backend = \"px4\"\n"));
    assert_eq!(msg, "unknown backend `px4` for drone `d`");
    assert_eq!(at, "\"px4\"");
    let (msg, at, _) = error(&format!("{HOME}backend = \"mavlink\"\n"));
    assert_eq!(msg, "drone `d` has `backend = \"mavlink\"` but no `mavlink` address");
    assert_eq!(at, "\"mavlink\"");
    let (msg, _, _) = error(&format!("{HOME}backend = \"sim\"\nmavlink = \"udp:h:1\"\n"));
    assert_eq!(msg, "drone `d` has `backend = \"sim\"` and a `mavlink` address");
    let (msg, at, _) = error(&format!("{HOME}system_id = 1\n"));
    assert_eq!(msg, "`system_id` of drone `d` applies only to a MAVLink drone");
    assert_eq!(at, "system_id");
    let (msg, _, _) = error(&format!("{HOME}mavlink = \"udp:h:1\"\nsystem_id = 300\n"));
    assert_eq!(msg, "`system_id` of drone `d` must be a whole number from 1 to 255, found 300");
}

#[test]
fn attribute_problems() {
    let (msg, at, _) = error(&format!("{HOME}speed = 3\n"));
    assert_eq!(
        msg,
        "attribute `speed` of drone `d` has the name of a telemetry field, so `d.speed` could not read it"
    );
    assert_eq!(at, "speed");
    let (msg, at, _) = error(&format!("{HOME}\"call-sign\" = \"x\"\n"));
    assert_eq!(
        msg,
        "attribute `call-sign` is not a valid name, so mission code could not refer to it"
    );
    assert_eq!(at, "\"call-sign\"");
}

#[test]
fn targets_and_site_values() {
    let (msg, at, _) = error("[[targets]]\nat = [1, 2]\n");
    assert_eq!(msg, "a target has no `kind`");
    assert_eq!(at, "[[targets]]");
    let (msg, at, _) = error("[targets]\nkind = \"Body\"\n");
    assert_eq!(msg, "`targets` must be a list of tables, found a table");
    assert_eq!(at, "[targets]\nkind = \"Body\"");
    let (msg, at, _) = error("[site]\norigin = { lat = 91, lon = 0 }\n");
    assert_eq!(msg, "`lat` of `origin` must be between -90 and 90, found 91");
    assert_eq!(at, "91");
    let (msg, at, _) = error("[site]\norigin = { lat = 1 }\n");
    assert_eq!(msg, "`origin` has no `lon`");
    assert_eq!(at, "origin");
    let (msg, at, _) = error("[site]\nmin_separation = -1\n");
    assert_eq!(msg, "`min_separation` must be zero or more metres, found -1");
    assert_eq!(at, "-1");
    let (msg, at, _) = error("[site]\nmax_altitude = inf\n");
    assert_eq!(msg, "`max_altitude` must be a finite number");
    assert_eq!(at, "inf");
}

#[test]
fn every_problem_in_one_pass() {
    let text = "[site]\nfoo = 1\n[places]\nA = [1]\n[areas]\nB = [[0, 0]]\n\
        [drones.x]\nbattery = 101\nsensors = [\"nope\"]\n[[faults]]\ndrone = \"y\"\nat = 1\nkind = \"boom\"\n";
    let all = errors(text);
    let spans: Vec<&str> = all.iter().map(|(_, at, _)| at.as_str()).collect();
    assert_eq!(spans, ["foo", "[1]", "[[0, 0]]", "x", "101", "\"nope\"", "\"y\"", "\"boom\""]);
}

#[test]
fn garbage_gives_diagnostics_not_panics() {
    let garbage = [
        "\0\u{1}\u{2}\u{7f}",
        "\u{feff}[site",
        "[[[[",
        "]]]]",
        "= = =",
        "x = 99999999999999999999999999",
        "x = 1e999",
        "[places]\nA = [1e308, -1e308]\nB = [1e308, 1e308, 1e308]",
        "[areas]\nA = [[1e308, 1e308], [-1e308, 1e308], [0, -1e308]]",
        "[drones.d]\nhome = [nan, 0]",
        "places = 1979-05-27",
        "[faults]\nx = 1",
        "faults = [1, 2]",
        "targets = [[1]]",
        "drones = []",
        "[drones]\nd = 5",
        "[drones.d.home]\nx = 1",
        "\"$__serde_spanned_private_start\" = 1",
        "[\"$__toml_private_datetime\"]\nx = 1",
        "a = { \"$__toml_private_datetime\" = \"x\" }",
    ];
    for text in garbage {
        let (world, diags) = parse(text);
        for d in &diags {
            assert!(text.get(d.primary.span.range()).is_some(), "{text:?}: {d:?}");
        }
        if text.starts_with("[places]") || text.starts_with("[areas]") {
            assert!(world.is_some(), "{text:?}: {diags:?}");
        } else {
            assert!(world.is_none() && !diags.is_empty(), "{text:?}");
        }
    }
    let deep = format!("a = {}{}", "[".repeat(5000), "]".repeat(5000));
    assert!(parse(&deep).0.is_none());
    let deep = format!("a = {}", "{ b = ".repeat(5000));
    assert!(parse(&deep).0.is_none());
    // A million open brackets on a test thread's small stack: the reader does not
    // recurse that deep (the TOML parser has a limit).
    for open in ["[", "{ b = ", "[{ b = "] {
        let (world, diags) = parse(&format!("a = {}", open.repeat(1_000_000)));
        assert!(world.is_none() && diags.iter().any(|d| d.is_error()), "{open}");
    }
}

/// Random texts and random edits of the example: never a panic, every span in the text.
#[test]
fn random_inputs_never_panic() {
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let alphabet: Vec<char> = "[]{}=,.\"'#\n \t0123456789-+eE_abcxyzAB:\\\u{0}é".chars().collect();
    for round in 0..3000 {
        let text: String = if round % 2 == 0 {
            let len = (next() % 80) as usize;
            (0..len).map(|_| alphabet[(next() % alphabet.len() as u64) as usize]).collect()
        } else {
            let mut chars: Vec<char> = EXAMPLE.chars().collect();
            for _ in 0..(next() % 4 + 1) {
                let at = (next() % chars.len() as u64) as usize;
                match next() % 3 {
                    0 => {
                        chars.remove(at);
                    }
                    1 => chars.insert(at, alphabet[(next() % alphabet.len() as u64) as usize]),
                    _ => chars[at] = alphabet[(next() % alphabet.len() as u64) as usize],
                }
            }
            chars.into_iter().collect()
        };
        let (world, diags) = parse(&text);
        assert_eq!(world.is_some(), diags.is_empty(), "{text:?}");
        for d in &diags {
            assert!(text.get(d.primary.span.range()).is_some(), "{text:?}: {d:?}");
        }
    }
}

/// Groups in order of first appearance, members in file order; one string for a group's
/// name and for each attribute key, whatever the drones.
#[test]
fn groups_and_attribute_keys_are_shared() {
    let sensors = "[sensors.thermal]\ndetects = [\"Body\"]\nrange = 20\n";
    let fleet = "[drones.a]\nhome = [0, 0]\ngroup = \"g\"\nsensors = [\"thermal\", \"camera\"]\nindex = 0\n\
                 [drones.b]\nhome = [5, 0, 1]\ngroup = \"h\"\npayload = [\"kit\"]\nnote = \"x\"\nlist = [1, 2]\n\
                 [drones.c]\nhome = [9, 9]\ngroup = \"g\"\nmavlink = \"udp:127.0.0.1:14550\"\nsystem_id = 3\n";
    // `[sensors]` after the drones that name them.
    let world = ok(&format!("{fleet}{sensors}"));
    assert_eq!(world.groups.len(), 2);
    assert_eq!(world.groups[0].members, [0, 2]);
    assert_eq!(*world.drones[0].sensors, ["thermal", "camera"]);
    let (a, c) = (&world.drones[0], &world.drones[2]);
    assert!(std::sync::Arc::ptr_eq(a.group.as_ref().unwrap(), c.group.as_ref().unwrap()));
    let w = ok("[drones.d]\nhome = [0, 0]\nnote = 1\n[drones.e]\nhome = [0, 0]\nnote = \"x\"\n");
    assert!(std::sync::Arc::ptr_eq(&w.drones[0].attributes[0].0, &w.drones[1].attributes[0].0));
}

/// Many drone tables, in groups.
#[test]
fn a_world_of_many_drone_tables() {
    let mut text = String::from("[site]\nname = \"W\"\n");
    for i in 0..500 {
        text.push_str(&format!(
            "\n[drones.a{i}]\nhome = [{}, 0]\ngroup = \"fleet{}\"\nindex = {i}\n",
            i * 5,
            i % 3
        ));
    }
    let world = ok(&text);
    assert_eq!(world.drones.len(), 500);
    assert_eq!(world.drones[499].name, "a499");
    assert_eq!(world.groups.iter().map(|g| g.members.len()).collect::<Vec<_>>(), [167, 167, 166]);
}

#[test]
fn a_world_without_air_is_still_and_the_mean_wind_is_where_it_blows_to() {
    assert!(ok("[drones.d]\nhome = [0, 0]\n").air.is_still());
    let w = ok("[drones.d]\nhome = [0, 0]\n[air.wind]\nspeed = 5\nfrom = 270\n");
    let wind = w.air.wind.expect("a wind");
    // A west wind blows east.
    let v = wind.velocity();
    assert!((v[0] - 5.0).abs() < 1e-12 && v[1].abs() < 1e-12, "{v:?}");
    assert_eq!((wind.turbulence, wind.drain), (None, 0.5));
    let north = ok("[drones.d]\nhome = [0, 0]\n[air.wind]\nspeed = 2\nfrom = 0\n");
    let v = north.air.wind.expect("a wind").velocity();
    assert!(v[0].abs() < 1e-12 && (v[1] + 2.0).abs() < 1e-12, "{v:?}");
    // A wind of 0 needs no direction.
    assert!(ok("[drones.d]\nhome = [0, 0]\n[air.wind]\nspeed = 0\n").air.wind.is_some());
}

#[test]
fn a_fleets_air_is_each_of_its_drones() {
    let w = ok("[fleets.r]\ncount = 3\nhomes = { grid = [0, 0], spacing = 10 }\nair = { relay = true, range = 400 }\n");
    assert!(w
        .drones
        .iter()
        .all(|d| d.air.as_deref().is_some_and(|a| a.relay && a.range == Some(400.0))));
    let w = ok(
        "[drones.d]\nhome = [0, 0]\n[drones.d.air]\ngps_error = 1.5\nfaults = { crash = 0.5 }\n",
    );
    let air = w.drones[0].air.as_deref().expect("its air");
    assert_eq!(air.gps_error, Some(1.5));
    assert_eq!(air.faults, vec![RandomFault { kind: FaultKind::Crash, rate: 0.5, duration: None }]);
}

#[test]
fn falloff_curves_and_their_reach() {
    let linear = Falloff::Linear;
    assert_eq!((linear.factor(0.0), linear.factor(0.25), linear.factor(1.5)), (1.0, 0.75, 0.0));
    assert!((linear.reach(0.25).unwrap() - 0.75).abs() < 1e-12);
    assert_eq!(linear.reach(1.0), None);
    let curve = Falloff::Curve(vec![[0.0, 1.0], [0.5, 1.0], [1.0, 0.2]]);
    assert_eq!(curve.factor(0.3), 1.0);
    assert!((curve.factor(0.75) - 0.6).abs() < 1e-12);
    // Found within 0.75 of the range for a draw of 0.6, within all of it for 0.1.
    assert!((curve.reach(0.6).unwrap() - 0.75).abs() < 1e-12);
    assert_eq!(curve.reach(0.1), Some(1.0));
    // Every level's reach is where the factor falls to it.
    for level in [0.21, 0.3, 0.5, 0.9, 0.99] {
        let r = curve.reach(level).unwrap();
        assert!((curve.factor(r) - level).abs() < 1e-9, "{level}: {r}");
    }
}

#[test]
fn random_fault_rates_keep_the_kinds_order_and_default_durations() {
    let w = ok("[drones.d]\nhome = [0, 0]\n[air.faults]\nmotor_failure = 0.01\ngps_loss = 0.5\nlink_loss = { rate = 1, duration = 20 }\n");
    let got: Vec<(FaultKind, f64, Option<f64>)> =
        w.air.faults.iter().map(|f| (f.kind, f.rate, f.duration)).collect();
    assert_eq!(
        got,
        vec![
            (FaultKind::LinkLoss, 1.0, Some(20.0)),
            (FaultKind::GpsLoss, 0.5, Some(10.0)),
            (FaultKind::MotorFailure, 0.01, None),
        ]
    );
    let (msg, at, _) = error("[drones.d]\nhome = [0, 0]\n[air.faults]\ngps_loss = -1\n");
    assert!(msg.contains("zero or more per flight hour"), "{msg}");
    assert_eq!(at, "-1");
}
