//! The simulator benchmark: N drones, each sweeping a square cell of its own with
//! detection on, and handlers for the finds. Cells tile a square grid; every third cell
//! hides a `Body` target, so finds keep coming while the fleet flies.

use std::fmt::Write;

/// Metres on a side of each drone's cell.
pub const CELL: usize = 100;
/// Metres from one cell's corner to the next: the cells are apart by more than the
/// separation planner's reach (about 160 m at 10 m/s), so each drone flies its own sky.
pub const PITCH: usize = 300;
/// Metres from a cell's corner to its drone's home, east and north.
const HOME: usize = 5;
/// Lane spacing of each sweep, metres.
const SPACING: usize = 25;

/// The swarm mission for `n` drones `s0` to `s{n-1}`, each with its cell `Cell_i`.
pub fn swarm_mission(n: usize) -> String {
    let mut m = String::with_capacity(1024 + 32 * n);
    let _ = writeln!(m, "// The swarm benchmark: {n} drones, each sweeping its own {CELL} m cell with detection on.");
    m.push_str(
        "CAPABILITY Survey BY d WITH cell:\n\
         \x20   PERFORM:\n\
         \x20       ON EVERY Detected BY d WITH kind, location:\n\
         \x20           SIGNAL Found WITH location\n\
         \x20       d TakeOff WITH 20m\n\
         \x20       d.StartDetection(Body)\n",
    );
    let _ = writeln!(m, "        d.Sweep(cell, {SPACING}m)");
    m.push_str(
        "        d.StopDetection(Body)\n\
         \x20       d ReturnHome\n\n\
         MISSION Swarm:\n\
         \x20   // Every find, whoever made it.\n\
         \x20   ON EVERY Found WITH location:\n\
         \x20       WAITFOR distance(location, location) < 1m\n\
         \x20   PARALLEL FOR\n",
    );
    for i in 0..n {
        let and = if i + 1 < n { " AND" } else { "" };
        let _ = writeln!(m, "        s{i} WITH Cell_{i}{and}");
    }
    m.push_str("        AS d WITH cell:\n        d Survey WITH cell\n");
    m
}

/// The world: one fleet, drone `s{i}` 5 m inside the south-west corner of its cell,
/// cells on a square grid (row by row), each drone's cell `Cell_{i}` the square 10 m
/// inside its own, a thermal camera on every drone and a `Body` in every third cell.
pub fn swarm_world(n: usize) -> String {
    let side = (n as f64).sqrt().ceil().max(1.0) as usize;
    let mut w = String::with_capacity(512 + 40 * n.div_ceil(3));
    let (near, far) = (10 - HOME, CELL - 10 - HOME);
    let _ = write!(
        w,
        "[site]\nname = \"Swarm\"\norigin = {{ lat = 46.6, lon = 14.2, alt = 440.0 }}\nmax_altitude = 120.0\n\n\
         [fleets.s]\ncount = {n}\nnames = \"s{{i}}\"\n\
         homes = {{ grid = [{HOME}, {HOME}], spacing = {PITCH}, columns = {side} }}\n\
         sensors = [\"thermal\"]\n\
         areas = {{ names = \"Cell_{{i}}\", polygon = [[{near}, {near}], [{far}, {near}], [{far}, {far}], [{near}, {far}]] }}\n"
    );
    w.push_str("\n[sensors.thermal]\ndetects = [\"Body\"]\nrange = 15.0\n");
    let corner = |i: usize| ((i % side) * PITCH, (i / side) * PITCH);
    for i in (0..n).step_by(3) {
        let (x, y) = corner(i);
        let _ = write!(
            w,
            "\n[[targets]]\nkind = \"Body\"\nat = [{}, {}]\n",
            x + 30 + (i * 7) % 40,
            y + 30 + (i * 13) % 40
        );
    }
    w
}

#[cfg(test)]
mod tests {
    use std::fmt::Write;

    use aviary_diagnostics::FileId;

    use super::*;

    /// The swarm's world as a table per drone and an area per line: what the fleet stands
    /// for, drone for drone and area for area.
    fn as_tables(n: usize) -> String {
        let side = (n as f64).sqrt().ceil().max(1.0) as usize;
        let mut w = String::from("[site]\nname = \"Swarm\"\norigin = { lat = 46.6, lon = 14.2, alt = 440.0 }\nmax_altitude = 120.0\n\n[areas]\n");
        let corner = |i: usize| ((i % side) * PITCH, (i / side) * PITCH);
        for i in 0..n {
            let (x, y) = corner(i);
            let (x1, y1) = (x + CELL - 10, y + CELL - 10);
            let (x0, y0) = (x + 10, y + 10);
            let _ =
                writeln!(w, "Cell_{i} = [[{x0}, {y0}], [{x1}, {y0}], [{x1}, {y1}], [{x0}, {y1}]]");
        }
        for i in 0..n {
            let (x, y) = corner(i);
            let _ = write!(
                w,
                "\n[drones.s{i}]\nhome = [{}, {}]\nsensors = [\"thermal\"]\nindex = {i}\n",
                x + 5,
                y + 5
            );
        }
        let fleet = swarm_world(n);
        w.push_str(&fleet[fleet.find("\n[sensors.thermal]").unwrap()..]);
        w
    }

    #[test]
    fn the_fleet_is_the_drones_and_cells_of_a_table_each() {
        for n in [1, 7, 40, 101] {
            let read = |text: &str| {
                let (world, diags) = aviary_world::parse_world(FileId(0), text);
                assert!(diags.is_empty(), "{diags:#?}");
                let mut world = world.unwrap();
                world.drones.iter_mut().for_each(|d| d.span = Default::default());
                world.areas.iter_mut().for_each(|a| a.span = Default::default());
                world.sensors.iter_mut().for_each(|s| s.span = Default::default());
                world
            };
            assert_eq!(read(&swarm_world(n)), read(&as_tables(n)), "{n} drones");
        }
    }
}
