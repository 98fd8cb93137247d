//! `aviary export TRACE --mcap BAG [--world W]`: a recorded trace as a ROS 2 bag
//! (`aviary_ros::bag`), for `ros2 bag`, rosbags and Foxglove. The world the trace flew in
//! (found as `aviary report` finds it) places the drones on the Earth; without one, the
//! bag has their poses in the local frame only.

use std::path::Path;

use aviary_api::trace::Record;

pub fn run(trace: &Path, world: Option<&Path>, bag: &Path) -> u8 {
    let (name, bytes, world) = match crate::files::recorded_trace_and_world(trace, world) {
        Ok(read) => read,
        Err(shown) => {
            eprint!("{shown}");
            return 2;
        }
    };
    let mut records: Vec<Record<'static>> = Vec::new();
    for (i, line) in String::from_utf8_lossy(&bytes).lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str(line) {
            Ok(record) => records.push(record),
            Err(e) => {
                eprintln!("aviary: {name}:{}: not an event of a trace ({e})", i + 1);
                eprintln!("  {line}");
                return 2;
            }
        }
    }
    let origin = world.as_ref().and_then(|w| w.site.origin.as_ref()).map(aviary_world::Geo::origin);
    if origin.is_none() {
        eprintln!("aviary: no world with an origin: the bag has the drones' poses in the local frame, no positions on the Earth");
    }
    match aviary_ros::bag::write(bag, &records, origin) {
        Ok(written) => {
            eprintln!("aviary: wrote {} ({})", bag.display(), written.file.display());
            for t in &written.topics {
                eprintln!("  {} ({}): {} messages", t.name, t.ty, t.messages);
            }
            0
        }
        Err(why) => {
            eprintln!("aviary: {why}");
            2
        }
    }
}
