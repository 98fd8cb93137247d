//! The real-autopilot test suites run only where their autopilot is named: `AVIARY_SITL`
//! (an ArduCopter SITL binary) turns on `cfg(arducopter_sitl)`, `AVIARY_PX4` (a PX4 SITL
//! `px4` binary) turns on `cfg(px4_sitl)`. `AVIARY_ZENOHD` (the `zenohd` router) turns on
//! `cfg(zenohd)`, for the three-machine test. Without them those tests are ignored, each
//! with the line that says how to run it, so a fresh clone's `cargo test` passes and
//! says what it did not fly. Naming a binary later rebuilds the tests, not the crates.

fn main() {
    for (var, cfg) in [
        ("AVIARY_SITL", "arducopter_sitl"),
        ("AVIARY_PX4", "px4_sitl"),
        ("AVIARY_ZENOHD", "zenohd"),
    ] {
        println!("cargo::rerun-if-env-changed={var}");
        println!("cargo::rustc-check-cfg=cfg({cfg})");
        if std::env::var_os(var).is_some_and(|v| !v.is_empty()) {
            println!("cargo::rustc-cfg={cfg}");
        }
    }
}
