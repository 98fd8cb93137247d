//! The shapes that once made the pre-flight analyses quadratic, for `aviary bench front`
//! and for tests: N statements in one `SEQUENTIAL` block, all on one drone (every pair of
//! them claims the same resource, so a pairwise comparison costs N²), and a chain of N
//! capabilities each calling the next (a fixpoint that learns one link per round costs
//! N²). Both check clean apart from the plan's honest findings.

use std::fmt::Write;

/// The world of both shapes: one drone, two places, a geofence around them.
pub fn front_world() -> String {
    "[site]\nname = \"Front\"\ngeofence = [[-500, -500], [500, -500], [500, 500], [-500, 500]]\nmax_altitude = 120\n\n\
     [places]\nHome = [0, 0]\nNorth = [0, 200]\nEast = [200, 0]\n\n\
     [drones.scout]\nhome = [0, 0]\nendurance = 1800\n"
        .to_string()
}

/// A mission of `n` statements in one `SEQUENTIAL` block, all on `scout`: a take-off,
/// then flights, hovers and climbs in turn, and a return home.
pub fn sequential_mission(n: usize) -> String {
    let mut m = String::with_capacity(64 + 34 * n);
    m.push_str("MISSION Long_Patrol:\n    SEQUENTIAL Steps:\n        scout TakeOff WITH 20m\n");
    for i in 1..n.saturating_sub(1) {
        let line = match i % 4 {
            0 => "        scout FlyTo WITH North\n",
            1 => "        scout Hover WITH 2s\n",
            2 => "        scout FlyTo WITH East\n",
            _ => "        scout FlyCircle WITH center=Home, radius=50m\n",
        };
        m.push_str(line);
    }
    if n > 1 {
        m.push_str("        scout ReturnHome\n");
    }
    m
}

/// A mission that calls `C0`, which calls `C1`, ..., down to `C{n-1}`, which hovers:
/// capability calls nested `n` deep.
pub fn chain_mission(n: usize) -> String {
    let mut m = String::with_capacity(96 + 60 * n);
    m.push_str("MISSION Chain:\n    scout TakeOff WITH 20m\n    scout C0\n    scout ReturnHome\n");
    for i in 0..n {
        let _ = write!(m, "\nCAPABILITY C{i} BY drone:\n    PERFORM:\n        ");
        if i + 1 < n {
            let _ = writeln!(m, "drone C{}", i + 1);
        } else {
            m.push_str("drone.Hover(1s)\n");
        }
    }
    m
}
