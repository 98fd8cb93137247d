//! What the start of a step reads of every drone, in a compact array beside the fleet:
//! whether it is in the air, where, its envelope's extent bound, and whether a step would
//! change it at all. Taken at the end of the drone's turn in a step, so that the next
//! step's first pass and its idle drones never touch the large `SimDrone`s. Anything that
//! changes a drone outside its own turn (a call, an interrupt, a fault) must
//! [`Fleet::touch`](crate::fleet::Fleet::touch) it: the copy is then taken afresh.

use crate::drone::SimDrone;
use crate::separation::extent_bound;

#[derive(Clone, Copy, Debug)]
pub(crate) struct Hot {
    /// False: not current, take it again from the drone.
    pub known: bool,
    /// In an airborne state.
    pub up: bool,
    /// On the ground with nothing to do: a step would change nothing of it.
    pub idle: bool,
    pub xy: [f64; 2],
    /// [`extent_bound`] when `up`, else NaN.
    pub extent: f64,
}

impl Hot {
    pub const UNKNOWN: Hot =
        Hot { known: false, up: false, idle: false, xy: [0.0; 2], extent: f64::NAN };

    pub fn of(d: &SimDrone) -> Hot {
        let up = d.state.airborne();
        Hot {
            known: true,
            up,
            idle: idle(d),
            xy: d.xy(),
            extent: if up { extent_bound(d) } else { f64::NAN },
        }
    }
}

/// Whether a step would change nothing of the drone: on the ground, with nothing to do
/// (no move, load, detection or yield in progress, at rest).
fn idle(d: &SimDrone) -> bool {
    !d.state.airborne()
        && d.motion.is_none()
        && d.loading().is_none()
        && d.detections().is_empty()
        && d.avoid.is_none()
        && d.stalled == 0.0
        && d.vel.iter().all(|v| v.to_bits() == 0)
}

/// Every step of every test checks the copies against the drones, and every "clear" of
/// the bound against the exact test.
#[cfg(test)]
impl crate::fleet::Fleet {
    pub(crate) fn check_hot(&self) {
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        for (id, (h, d)) in self.hot.iter().zip(&self.drones).enumerate() {
            let now = Hot::of(d);
            if h.known {
                assert!(
                    h.up == now.up
                        && h.idle == now.idle
                        && same(h.xy[0], now.xy[0])
                        && same(h.xy[1], now.xy[1])
                        && same(h.extent, now.extent),
                    "drone {id}: kept {h:?}, now {now:?}"
                );
            }
        }
    }

    pub(crate) fn check_clear(&self, id: usize, r: f64) {
        let mut sky = crate::grid::Grid::new(100.0);
        for &j in &self.aloft {
            sky.put(j, self.drones[j].xy());
        }
        assert!(
            !sky.any_within(self.drones[id].xy(), r, id),
            "drone {id} is not clear within {r} m"
        );
    }
}
