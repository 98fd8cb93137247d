//! `aviary vehicles`: serves the drones of a world as ArduCopter-like or PX4 MAVLink
//! vehicles (the `aviary-vehicles` crate) until Ctrl-C.

use std::path::Path;

use aviary_diagnostics::{render_text, SourceMap};

use crate::files::color_wanted;

/// `--autopilot`: whose behaviour the vehicles have.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Autopilot {
    /// ArduCopter's (the default)
    Ardupilot,
    /// PX4's
    Px4,
}

pub struct VehiclesArgs<'a> {
    pub world: &'a Path,
    pub listen: &'a str,
    pub speed: f64,
    pub signing_key: Option<&'a str>,
    pub autopilot: Autopilot,
}

pub fn run(args: &VehiclesArgs) -> u8 {
    let listen = match aviary_vehicles::parse_listen(args.listen) {
        Ok(l) => l,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    if !(args.speed.is_finite() && args.speed > 0.0) {
        eprintln!("aviary: --speed must be a positive number of times real time, such as 1 or 20");
        return 2;
    }
    let bytes = match std::fs::read(args.world) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("aviary: cannot read the world file {}: {e}", args.world.display());
            return 2;
        }
    };
    let mut sources = SourceMap::new();
    let name = args.world.display().to_string();
    // With its `[imports]`, read beside it.
    let read = aviary_check::read_world(
        &mut sources,
        &name,
        std::borrow::Cow::Owned(bytes),
        &crate::files::world_files(),
    );
    let (world, diagnostics) = (read.world, read.diagnostics);
    let errors: Vec<_> = diagnostics.iter().filter(|d| d.is_error()).collect();
    let Some(world) = world.filter(|_| errors.is_empty()) else {
        for d in errors {
            eprint!("{}", render_text(&sources, d, color_wanted()));
        }
        eprintln!("aviary: {name} has errors");
        return 2;
    };
    let runtime =
        match tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build() {
            Ok(r) => r,
            Err(e) => {
                eprintln!("aviary: cannot start the runtime: {e}");
                return 2;
            }
        };
    let autopilot = match args.autopilot {
        Autopilot::Ardupilot => aviary_vehicles::Flavour::ArduPilot,
        Autopilot::Px4 => aviary_vehicles::Flavour::Px4,
    };
    let options = aviary_vehicles::Options {
        speed: args.speed,
        signing_key: args.signing_key.map(aviary_mavlink::signing_key),
        behaviour: aviary_vehicles::Behaviour {
            autopilot,
            ..aviary_vehicles::Behaviour::default()
        },
    };
    runtime.block_on(async {
        let server = match aviary_vehicles::serve(&world, listen, options).await {
            Ok(s) => s,
            Err(e) => {
                eprintln!("aviary: cannot listen on {}: {e}", args.listen);
                return 2;
            }
        };
        let scheme = if matches!(listen, aviary_vehicles::Listen::Tcp(_)) { "tcp" } else { "udp" };
        // The first line says where: tests and scripts read the port from it.
        // Written without println!, which would panic once a reader closes the pipe.
        use std::io::Write;
        let mut out = std::io::stdout();
        let _ = writeln!(out, "aviary vehicles: listening on {scheme}:{}", server.address);
        for (i, d) in world.drones.iter().enumerate() {
            let _ = writeln!(out, "  {} = system {}", d.name, server.systems[i]);
        }
        let _ = out.flush();
        let _ = tokio::signal::ctrl_c().await;
        server.stop();
        0
    })
}
