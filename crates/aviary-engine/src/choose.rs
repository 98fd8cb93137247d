//! `ANY d IN group WHERE c NEAREST TO p WITHIN t:`: drones chosen at run time.
//!
//! A drone an `ANY` takes is held until its body ends: no other `ANY` takes it
//! meanwhile. Holding is the engine's own bookkeeping, apart from resource claims: a
//! statement that names the drone directly still waits for its resources as usual.
//! The choice is made at one instant, from what telemetry says then, so two `ANY`s that
//! look at once are served in the order they look, and never share a drone.

use std::cell::RefCell;
use std::time::Duration;

use aviary_api::{BuiltinException, DroneId, FlightState, Value};
use aviary_ir::{Any, TiVec};

use crate::engine::{Ctx, Engine};
use crate::exec::{set, RECHECK};
use crate::join::join_in_order;

/// Which drones an `ANY` holds, by drone.
#[derive(Default)]
pub(crate) struct Taken(RefCell<TiVec<DroneId, bool>>);

impl Taken {
    pub fn holds(&self, d: DroneId) -> bool {
        self.0.borrow().get(d).copied().unwrap_or(false)
    }

    fn set(&self, d: DroneId, held: bool) {
        let mut taken = self.0.borrow_mut();
        if taken.len() <= d.0 {
            taken.resize(d.0 + 1, false);
        }
        taken[d] = held;
    }
}

/// Lets a drone go when its body ends, however it ends (done, aborted, dropped).
struct Release<'e, 'm> {
    engine: &'e Engine<'m>,
    drone: DroneId,
}

impl Drop for Release<'_, '_> {
    fn drop(&mut self) {
        self.engine.taken.set(self.drone, false);
        // An `ANY` waiting for a free drone looks again at once.
        self.engine.changed.notify_waiters();
    }
}

/// Why an `ANY` cannot be served.
enum Wait {
    /// Not yet: too few candidates are free and fit now.
    Later,
    /// Never: too few candidates are left in the mission at all.
    Never(usize),
}

impl<'m> Engine<'m> {
    pub(crate) async fn any(&self, a: &'m Any, ctx: &Ctx<'m>) {
        let within =
            a.within.as_ref().map(|t| match self.eval_all(std::slice::from_ref(t), ctx).first() {
                Some(Value::Number(s)) if s.is_finite() => s.clamp(0.0, 1e9),
                _ => 0.0,
            });
        let deadline = within.map(|s| aviary_clock::Instant::now() + Duration::from_secs_f64(s));
        let chosen = loop {
            let changed = self.changed.notified();
            match self.choose(a, ctx) {
                Ok(chosen) => break chosen,
                Err(Wait::Never(left)) => {
                    let why = format!(
                        "ANY needs {} of {}, and only {left} of them are still in the mission",
                        a.count, a.group
                    );
                    return self.no_drone(a, why, ctx);
                }
                Err(Wait::Later) => {}
            }
            let timed_out = async {
                match deadline {
                    Some(at) => aviary_clock::sleep_until(at).await,
                    None => std::future::pending().await,
                }
            };
            tokio::select! {
                biased;
                _ = changed => {}
                _ = aviary_clock::sleep(RECHECK) => {}
                _ = timed_out => {
                    // The last look, at the deadline itself.
                    if let Ok(chosen) = self.choose(a, ctx) {
                        break chosen;
                    }
                    let why = format!(
                        "ANY found no {} of {} free and fit within {} s",
                        if a.count == 1 { "drone".to_string() } else { format!("{} drones", a.count) },
                        a.group,
                        within.unwrap_or(0.0)
                    );
                    return self.no_drone(a, why, ctx);
                }
            }
            if self.stopped() || ctx.scope.unwinding.get() {
                return;
            }
        };
        let runs: Vec<(Ctx<'m>, Release<'_, 'm>)> = chosen
            .into_iter()
            .map(|d| {
                self.taken.set(d, true);
                let mut frame = ctx.frame.to_vec();
                set(&mut frame, a.alias, Value::Actor(d));
                let inner = Ctx { frame: std::rc::Rc::from(frame), actor: Some(d), ..ctx.clone() };
                (inner, Release { engine: self, drone: d })
            })
            .collect();
        // Each drone is let go as its own body ends, not when the last of them does.
        join_in_order(runs.into_iter().map(|(c, release)| async move {
            self.block(&a.body, &c).await;
            drop(release);
        }))
        .await;
    }

    /// The drones `a` takes now, nearest first, or why it cannot take them.
    fn choose(&self, a: &Any, ctx: &Ctx<'m>) -> Result<Vec<DroneId>, Wait> {
        let received = self.received.borrow();
        let env = self.env(&ctx.frame, &received);
        let mut frame = ctx.frame.to_vec();
        let mut left = 0;
        let mut fit: Vec<DroneId> = Vec::new();
        for &d in &a.candidates {
            let gone = self.backend.telemetry(d).state == FlightState::Lost
                || self.steering.withdrawn(d).is_some();
            if gone {
                continue;
            }
            left += 1;
            if self.taken.holds(d) {
                continue;
            }
            let meets = match &a.condition {
                Some(c) => {
                    set(&mut frame, a.alias, Value::Actor(d));
                    self.env(&frame, &received).truth(c)
                }
                None => true,
            };
            if meets {
                fit.push(d);
            }
        }
        if left < a.count {
            return Err(Wait::Never(left));
        }
        if fit.len() < a.count {
            return Err(Wait::Later);
        }
        if let Some(p) = &a.nearest {
            let target = env.position(&env.eval(p));
            let away = |d: DroneId| {
                let at = self.backend.telemetry(d).gps_position;
                (at[0] - target[0]).hypot(at[1] - target[1])
            };
            // Stable: of drones equally near, the group's order decides.
            fit.sort_by(|&x, &y| away(x).total_cmp(&away(y)));
        }
        fit.truncate(a.count);
        Ok(fit)
    }

    /// `NoDroneAvailable`, thrown where the `ANY` stands, with why.
    fn no_drone(&self, a: &Any, why: String, ctx: &Ctx<'m>) {
        let exception = self.m.builtins.exception(BuiltinException::NoDroneAvailable);
        self.throw(exception, vec![Value::Text(why)], ctx.actor, &ctx.scope, Some(a.origin), None);
    }
}
