//! The compiler on the paper's mission and on small missions: names become indices,
//! handlers sit on the block they hear, defaults and units are resolved once.

use aviary_api::{BuiltinLeash, DroneId, FunctionCall, Point, Resource, Value};
use aviary_ir::*;
use aviary_lower::compile;
use aviary_test_support::harness;

fn compiled(mission: &str, world: &str) -> Mission {
    harness::compile(mission, world).0
}

fn paper() -> Mission {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/");
    compiled(
        &std::fs::read_to_string(format!("{root}search_and_rescue.mission")).unwrap(),
        &std::fs::read_to_string(format!("{root}search_and_rescue.world.toml")).unwrap(),
    )
}

fn block(node: &Node) -> &Block {
    match node {
        Node::Block(b) => b,
        other => panic!("not a block: {other:?}"),
    }
}

fn cap<'m>(m: &'m Mission, name: &str) -> &'m Capability {
    m.capabilities.iter().find(|c| c.name == name).unwrap_or_else(|| panic!("no {name}"))
}

#[test]
fn the_paper_mission_compiles_with_handlers_on_their_block() {
    let m = paper();
    assert_eq!(m.name, "Search_and_Rescue");
    assert_eq!(m.drones.len(), 7);
    let start = block(&m.body.items[0]);
    assert_eq!(start.path, "Start_Mission");
    assert_eq!(start.kind, BlockKind::Parallel);
    let children: Vec<&str> = start.items.iter().map(|n| block(n).path.as_str()).collect();
    assert_eq!(children, ["Launch_Video1", "Launch_Video2", "Radiation_Detection"]);
    let handlers: Vec<(&str, bool, &str)> = start
        .handlers
        .iter()
        .map(|h| (m.signals[h.signal].as_str(), h.every, h.body.path.as_str()))
        .collect();
    assert_eq!(
        handlers,
        [
            ("Video2_Ready", false, "Start_Mission/ON Video2_Ready"),
            ("Video1_Ready", false, "Start_Mission/ON Video1_Ready"),
            ("Radiation_Detected", true, "Start_Mission/ON Radiation_Detected"),
            ("Body_Detected", true, "Start_Mission/ON Body_Detected"),
        ]
    );
    let sensor = m.drones.position("sensor_drone").unwrap();
    assert_eq!(start.handlers[2].by, Some(ActorFilter::Drones(vec![sensor])));
    // `BY flir_drone` names the FOR alias of a sibling handler: any of its instances.
    let flirs: Vec<DroneId> =
        ["flir_drone1", "flir_drone2"].iter().map(|n| m.drones.position(n).unwrap()).collect();
    assert_eq!(start.handlers[3].by, Some(ActorFilter::Drones(flirs)));
}

#[test]
fn defaults_fill_missing_arguments_in_si_units() {
    let m = paper();
    let takeoff = m.capabilities.position(|c| c.name == "TakeOff").unwrap();
    let launch = block(&block(&m.body.items[0]).items[0]);
    let Node::Call(first) = &launch.items[0] else { panic!() };
    assert_eq!(first.capability, takeoff);
    assert_eq!(first.args, [Expr::Const(Value::Number(20.0))]);
    let radiation = block(&block(&m.body.items[0]).items[2]);
    let Node::Call(sensor_takeoff) = &radiation.items[0] else { panic!() };
    assert_eq!(
        sensor_takeoff.args,
        [Expr::Const(Value::Number(10.0))],
        "TakeOff's default alt is 10m"
    );
    let Node::Call(patrol) = &radiation.items[1] else { panic!() };
    assert_eq!(
        patrol.args,
        [
            Expr::Const(Value::Position(Point { x: 0.0, y: -300.0, z: None })),
            Expr::Const(Value::Number(30.0)),
            Expr::Const(Value::Number(1.0))
        ],
        "the place StartPos, then FlyToAndPatrol's defaults"
    );
}

#[test]
fn claims_reach_through_called_capabilities() {
    let m = paper();
    assert_eq!(cap(&m, "DeployBeacon").claims, [(0, Resource::Motion), (0, Resource::Payload)]);
    assert_eq!(cap(&m, "Search").claims, [(0, Resource::Motion), (0, Resource::Detection)]);
    assert_eq!(cap(&m, "StartStreaming").claims, [(0, Resource::Camera)]);
    assert_eq!(
        cap(&m, "FlyTo").claims,
        [(0, Resource::Motion)],
        "FlyTo's own call, and TakeOff's through it"
    );
}

#[test]
fn units_become_si_and_geo_becomes_local() {
    let m = compiled(
        "MISSION M:\n    d1 Hover WITH 2min\n    d1 Hover WITH 1.5h\n    STARTIF d1.battery > 25% AND d1.speed < 36km/h:\n        d1 FlyTo WITH GEO(46.6177, 14.2650, 460)\n",
        "[site]\norigin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }\n[drones.d1]\nhome = [0, 0]\n",
    );
    let Node::Call(h) = &m.body.items[0] else { panic!() };
    assert_eq!(h.args, [Expr::Const(Value::Number(120.0))]);
    let Node::Call(h) = &m.body.items[1] else { panic!() };
    assert_eq!(h.args, [Expr::Const(Value::Number(5400.0))]);
    let Node::StartIf { condition, body } = &m.body.items[2] else { panic!() };
    let Expr::And(battery, speed) = condition else { panic!("{condition:?}") };
    assert_eq!(
        **battery,
        Expr::Compare(
            Box::new(Expr::Telemetry(ActorRef::Drone(DroneId(0)), Field::Battery)),
            Compare::Gt,
            Box::new(Expr::Const(Value::Number(0.25)))
        )
    );
    let Expr::Compare(_, Compare::Lt, limit) = &**speed else { panic!() };
    assert_eq!(**limit, Expr::Const(Value::Number(10.0)));
    let Node::Call(fly) = &body.items[0] else { panic!() };
    // FlyTo's `speed` left out: its default, 0 m/s (the drone's own speed).
    let [Expr::Const(Value::Position(p)), Expr::Const(Value::Number(speed))] = fly.args.as_slice()
    else {
        panic!("{:?}", fly.args)
    };
    assert_eq!(*speed, 0.0);
    assert!(
        p.x.abs() < 1e-9 && (p.y - 111.19).abs() < 0.01 && (p.z.unwrap() - 20.0).abs() < 1e-9,
        "{p:?}"
    );
}

#[test]
fn for_instances_groups_and_slots() {
    let m = compiled(
        "MISSION M:\n    PARALLEL FOR\n        team WITH (1, 2) AND\n        d3 WITH (3, 4)\n        AS d WITH spot:\n        d FlyTo WITH spot\n        SIGNAL Here WITH d\n    ON EVERY Here BY d WITH who:\n        who Land\n",
        "[drones.d1]\nhome = [0, 0]\ngroup = \"team\"\n[drones.d2]\nhome = [5, 0]\ngroup = \"team\"\n[drones.d3]\nhome = [9, 0]\n",
    );
    let Node::For(f) = &m.body.items[0] else { panic!() };
    assert!(f.parallel);
    assert_eq!(f.instances[0].0, ActorRef::Group(vec![DroneId(0), DroneId(1)]));
    assert_eq!(f.instances[1].0, ActorRef::Drone(DroneId(2)));
    let Node::Call(fly) = &f.body.items[0] else { panic!() };
    assert_eq!(fly.actors, [ActorRef::Slot(f.alias)]);
    assert_eq!(fly.args, [Expr::Slot(f.params[0]), Expr::Const(Value::Number(0.0))]);
    let handler = &m.body.handlers[0];
    assert_eq!(
        handler.by,
        Some(ActorFilter::Drones(vec![DroneId(0), DroneId(1), DroneId(2)])),
        "the alias stands for every instance"
    );
    let Node::Call(land) = &handler.body.items[0] else { panic!() };
    assert_eq!(land.actors, [ActorRef::Slot(handler.bindings[0])]);
    assert!(m.frame_size >= 3);
}

#[test]
fn leashes_resolve_their_section_and_tag() {
    let m = compiled(
        "CAPABILITY Watch BY d WITH radius:\n    PERFORM:\n        d.Orbit((0, 0), radius)\n    PERFORM Wider:\n        d.Orbit((0, 0), radius)\n\nMISSION M:\n    PARALLEL:\n        d1 Watch-W1 WITH 20m\n        SEQUENTIAL:\n            d1 Hover WITH 5s\n            Watch-W1 Wider WITH radius=40m\n            Watch-W1 ABORT\n",
        "[drones.d1]\nhome = [0, 0]\n",
    );
    let par = block(&m.body.items[0]);
    let Node::Call(watch) = &par.items[0] else { panic!() };
    assert_eq!(watch.tag, Some(TagId(0)));
    assert_eq!(m.tags.raw, ["W1"]);
    let seq = block(&par.items[1]);
    assert_eq!(seq.path, "M/PARALLEL/SEQUENTIAL");
    let Node::Leash(wider) = &seq.items[1] else { panic!() };
    let watch_cap = &m.capabilities[wider.capability];
    assert_eq!(
        (wider.action, watch_cap.action_name(wider.action)),
        (LeashAction::Section(0), Some("Wider"))
    );
    assert_eq!(wider.args, [(0, Expr::Const(Value::Number(40.0)))]);
    let Node::Leash(abort) = &seq.items[2] else { panic!() };
    assert_eq!(abort.action, LeashAction::Builtin(BuiltinLeash::Abort));
}

/// The operator API checks a leash's arguments and a signal's values against these.
#[test]
fn the_inferred_kinds_of_parameters_and_signal_values_are_kept() {
    use aviary_api::Kind;
    let m = compiled(
        "MISSION M:\n    PARALLEL:\n        a FlyCircle-C1 WITH Far, 40m\n        ON Go WITH where:\n            a FlyTo WITH where\n",
        "[places]\nFar = [0, 400]\n[drones.a]\nhome = [0, 0]\n",
    );
    let circle = cap(&m, "FlyCircle");
    assert_eq!(circle.params, ["center", "radius", "laps"]);
    assert_eq!(circle.param_kinds, [Some(Kind::Position), Some(Kind::Length), Some(Kind::Number)]);
    let go = m.signals.position(|s| s == "Go").expect("Go is a signal");
    assert_eq!(m.signal_values[go], [Some(Kind::Position)]);
    let detected = m.signals.position(|s| s == "Detected").expect("a built-in signal");
    assert_eq!(m.signal_values[detected], [Some(Kind::Symbol), Some(Kind::Position)]);
}

/// What the engine raises by itself, and the section an abort runs, are resolved here:
/// the engine looks up no name for them (a missing one used to become index 0).
#[test]
fn builtins_and_the_abort_section_are_resolved_when_compiling() {
    let m = compiled(
        "CAPABILITY Watch BY d:\n    PERFORM:\n        d.Hover(100s)\n    PERFORM Look:\n        d.Hover(1s)\n    PERFORM ABORT:\n        SIGNAL Stopped\n\nMISSION M:\n    d1 Watch\n",
        "[drones.d1]\nhome = [0, 0]\n",
    );
    for s in aviary_api::BuiltinSignal::ALL {
        assert_eq!(m.signals[m.builtins.signal(s)], s.name());
    }
    for e in aviary_api::BuiltinException::ALL {
        assert_eq!(m.exceptions[m.builtins.exception(e)], e.name());
    }
    let watch = cap(&m, "Watch");
    assert_eq!(watch.abort_section.map(|k| watch.sections[k].0.as_str()), Some("ABORT"));
    let paper = paper();
    assert!(
        paper.capabilities.iter().all(|c| c.abort_section.is_none()),
        "the paper's mission has no ABORT section"
    );
}

/// Every built-in a backend may raise has an id of its own, never another name's id; the
/// mission's own names follow them.
#[test]
fn every_builtin_has_its_own_id() {
    let (_, checked) = harness::check(
        "MISSION M:\n    SIGNAL Go\n    THROW EXCEPTION Oops\n",
        "[drones.d1]\nhome = [0, 0]\n",
    );
    let m = compile(&checked.program.expect("program"), &checked.world.expect("world"))
        .expect("a mission");
    for s in aviary_api::BuiltinSignal::ALL {
        assert_eq!(m.signals[m.builtins.signal(s)], s.name());
    }
    for e in aviary_api::BuiltinException::ALL {
        assert_eq!(m.exceptions[m.builtins.exception(e)], e.name());
    }
    assert_eq!(m.signals[SignalId(aviary_api::BuiltinSignal::ALL.len())], "Go");
    assert_eq!(m.exceptions[ExceptionId(aviary_api::BuiltinException::ALL.len())], "Oops");
}

#[test]
fn operator_signals_become_ids_once_each_and_one_at_a_time_is_kept() {
    let m = compiled(
        "MISSION M:\n    OPERATOR SIGNAL Go, Stop\n    OPERATOR SIGNAL Never_Heard\n    PARALLEL P:\n        SIGNAL Go\n        ON EVERY Go ONE AT A TIME:\n            a Hover WITH 1s\n        ON EVERY Stop:\n            a Hover WITH 1s\n        ON Go:\n            a Hover WITH 1s\n",
        harness::WORLD,
    );
    let names: Vec<&str> = m.operator_signals.iter().map(|&s| m.signals[s].as_str()).collect();
    assert_eq!(names, ["Go", "Stop", "Never_Heard"], "in the order written, each a signal");
    assert!(m.body.items.len() == 1, "the declarations are no nodes: {:?}", m.body.items);
    let p = block(&m.body.items[0]);
    let flags: Vec<(bool, bool)> = p.handlers.iter().map(|h| (h.every, h.one_at_a_time)).collect();
    assert_eq!(flags, [(true, true), (true, false), (false, false)]);
    assert!(compiled("MISSION M:\n    a Hover WITH 1s\n", harness::WORLD)
        .operator_signals
        .is_empty());
}

#[test]
fn a_call_of_constants_is_read_when_compiled_and_one_of_parameters_when_made() {
    let m = compiled(
        "CAPABILITY Up BY d WITH alt:\n    PERFORM:\n        d.TakeOff(alt)\n        d.Hover(2min)\n        d.StartDetection(Body)\n\nMISSION M:\n    d1 Up WITH 10m\n",
        "[site]\norigin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }\n[drones.d1]\nhome = [0, 0]\n",
    );
    let calls: Vec<&ApiCall> = cap(&m, "Up")
        .perform
        .items
        .iter()
        .map(|n| match n {
            Node::Api(a) => a,
            other => panic!("not a call: {other:?}"),
        })
        .collect();
    assert_eq!(calls[0].read, None, "a parameter's value is known when the call is made");
    assert_eq!(calls[1].read, Some(FunctionCall::Hover { duration: 120.0 }));
    assert_eq!(calls[2].read, Some(FunctionCall::StartDetection { kind: "Body".into() }));
}
