//! One MAVLink drone of the world and the protocol steps every function is made of:
//! commands with ACK, retries and the autopilot's reason; mode changes confirmed by
//! HEARTBEAT; position targets; waits that always end.

use parking_lot::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use aviary_api::{BuiltinException, Failure, FlightState};
use aviary_clock::Instant;
use mavlink::dialects::ardupilotmega::{
    MavCmd, MavFrame, MavMessage, MavModeFlag, MavResult, PositionTargetTypemask, COMMAND_INT_DATA,
    COMMAND_LONG_DATA, SET_POSITION_TARGET_GLOBAL_INT_DATA,
};
use tokio::sync::watch;

use crate::link::Link;
use crate::mode::{self, Flavour, Mode};
use crate::vehicle::{Fix, Vehicle};
use crate::Tuning;

/// What a drone does now, for telemetry's `state` (the autopilot reports only armed,
/// mode and height, so the call in progress says whether it is taking off or landing).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Doing {
    Other,
    TakingOff,
    Landing,
}

pub struct Craft {
    pub name: String,
    pub link: Arc<Link>,
    pub v: Arc<Vehicle>,
    pub max_speed: f64,
    /// The `acceleration` (m/s², the vehicle's WPNAV_ACCEL when it answered): orbit speeds
    /// and where a path's points are passed.
    pub acceleration: f64,
    /// The battery rule's figures: the world's, with the vehicle's applied (`facts`).
    pub battery: crate::battery::Figures,
    pub home: [f64; 2],
    pub sensors: Vec<String>,
    pub payload: Vec<String>,
    pub fence: Option<Vec<[f64; 2]>>,
    pub max_altitude: Option<f64>,
    /// The geofence and the no-fly zones (one for every drone): transits go their route.
    pub airspace: Arc<aviary_route::Airspace>,
    /// `ReturnToLaunch` flies a detour home at least this high (the vehicle's RTL_ALT
    /// when it answered).
    pub return_altitude: f64,
    pub streaming: AtomicBool,
    pub carrying: Mutex<Option<String>>,
    pub doing: Mutex<Doing>,
    /// The ground speed last set with DO_CHANGE_SPEED.
    pub speed: Mutex<Option<f64>>,
    /// The altitude last commanded: a flight without one keeps it (as the simulator's
    /// drones do), not the height reported on the way up to it.
    pub level: Mutex<Option<f64>>,
    /// The point of the path being flown that the drone is flying to (its index in the
    /// path `motion::fly` was given), for where a `Sweep` or `FollowPath` stops
    /// (`Backend::stopped`). Set before the point's target is sent; cleared when a motion
    /// call starts.
    pub flying_to: Mutex<Option<usize>>,
    /// When the last target (PX4's DO_REPOSITION or DO_ORBIT) was sent, for
    /// [`Craft::refused`].
    pub targeted: Mutex<Option<Instant>>,
    pub tuning: Tuning,
}

/// How long a command the vehicle says is in progress is waited for, all told.
const IN_PROGRESS_LIMIT: Duration = Duration::from_secs(30);

pub fn failed(reason: impl Into<String>) -> Failure {
    Failure::new(BuiltinException::CommandFailed, reason)
}

pub fn timeout(reason: impl Into<String>) -> Failure {
    Failure::new(BuiltinException::Timeout, reason)
}

impl Craft {
    pub fn fix(&self) -> Option<Fix> {
        self.v.seen().fix
    }

    /// The altitude a flight without one keeps.
    pub fn level(&self) -> f64 {
        self.level.lock().or_else(|| self.fix().map(|f| f.pos[2])).unwrap_or(f64::NAN)
    }

    pub fn set_level(&self, z: Option<f64>) {
        *self.level.lock() = z;
    }

    pub fn flying_to(&self) -> Option<usize> {
        *self.flying_to.lock()
    }

    pub fn set_flying_to(&self, point: Option<usize>) {
        *self.flying_to.lock() = point;
    }

    pub fn set_doing(&self, doing: Doing) {
        *self.doing.lock() = doing;
    }

    pub fn state(&self) -> FlightState {
        let seen = self.v.seen();
        let z = seen.fix.map_or(0.0, |f| f.pos[2]);
        match *self.doing.lock() {
            _ if !seen.armed => FlightState::Landed,
            Doing::TakingOff => FlightState::TakingOff,
            Doing::Landing => FlightState::Landing,
            Doing::Other if z < 0.3 => FlightState::Landed,
            Doing::Other => FlightState::Flying,
        }
    }

    pub fn streaming(&self) -> bool {
        self.streaming.load(Ordering::SeqCst)
    }

    /// COMMAND_LONG with ACK: resent (with `confirmation` counting up) when no ACK comes,
    /// refused with the autopilot's STATUSTEXT as the reason.
    pub async fn command(&self, command: MavCmd, p: [f32; 7]) -> Result<(), Failure> {
        self.command_with(command, |confirmation| {
            MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
                param1: p[0],
                param2: p[1],
                param3: p[2],
                param4: p[3],
                param5: p[4],
                param6: p[5],
                param7: p[6],
                command,
                target_system: self.v.system,
                target_component: 1,
                confirmation,
            })
        })
        .await
    }

    /// COMMAND_INT (positions as degrees × 10⁷, the altitude in `frame`), with ACK.
    pub async fn command_int(
        &self,
        command: MavCmd,
        frame: MavFrame,
        p: [f32; 4],
        (lat, lon, z): (i32, i32, f32),
    ) -> Result<(), Failure> {
        self.command_with(command, |_| {
            MavMessage::COMMAND_INT(COMMAND_INT_DATA {
                param1: p[0],
                param2: p[1],
                param3: p[2],
                param4: p[3],
                x: lat,
                y: lon,
                z,
                command,
                target_system: self.v.system,
                target_component: 1,
                frame,
                current: 0,
                autocontinue: 0,
            })
        })
        .await
    }

    async fn command_with(
        &self,
        command: MavCmd,
        msg: impl Fn(u8) -> MavMessage,
    ) -> Result<(), Failure> {
        let started = Instant::now();
        for attempt in 0..self.tuning.command_tries {
            let mut ack = self.v.expect_ack(command);
            self.link.send(&msg(attempt)).await;
            let sent = std::time::Instant::now();
            let mut wait = self.tuning.ack_timeout;
            let result = loop {
                match aviary_clock::timeout(wait, &mut ack).await {
                    Ok(Ok(result)) => break Some(result),
                    // Said to be in progress (PX4's gripper): its final answer is waited for,
                    // not asked again, which PX4 would refuse as a second of the same.
                    Err(_)
                        if self.v.in_progress(command, started)
                            && started.elapsed() < IN_PROGRESS_LIMIT =>
                    {
                        continue
                    }
                    // Unanswered only when the time is up by the wall's clock too: the
                    // mission's follows the vehicles', and one that lags the others on a
                    // busy machine has had less of it (as for the link's timeout).
                    Err(_) if sent.elapsed() < self.tuning.ack_timeout => {
                        wait = self.tuning.poll;
                        continue;
                    }
                    _ => break None,
                }
            };
            match result {
                Some(MavResult::MAV_RESULT_ACCEPTED) => return Ok(()),
                Some(result) => {
                    // The reason usually comes just before the ACK; give a late one a moment.
                    aviary_clock::sleep(Duration::from_millis(50)).await;
                    let why =
                        self.v.texts_since(started).unwrap_or_else(|| "no reason given".into());
                    return Err(failed(format!(
                        "{} refused {command:?} ({result:?}): {why}",
                        self.name
                    )));
                }
                None => continue,
            }
        }
        Err(timeout(format!(
            "{} did not acknowledge {command:?} after {} tries ({} s each) on {}",
            self.name,
            self.tuning.command_tries,
            self.tuning.ack_timeout.as_secs_f64(),
            self.link.address
        )))
    }

    /// Waits (polling the last messages) until `done` holds, or fails after `limit`.
    pub async fn wait_for(
        &self,
        limit: Duration,
        what: &str,
        mut done: impl FnMut(&Craft) -> bool,
    ) -> Result<(), Failure> {
        let deadline = Instant::now() + limit;
        loop {
            if done(self) {
                return Ok(());
            }
            if Instant::now() >= deadline {
                return Err(timeout(format!(
                    "{}: {what} took longer than {:.0} s",
                    self.name,
                    limit.as_secs_f64()
                )));
            }
            aviary_clock::sleep(self.tuning.poll).await;
        }
    }

    /// Waits until the autopilot is ready (MAV_STATE_STANDBY, ACTIVE, or CRITICAL: up but
    /// in a failsafe, which arming will then report): a mode change sent while it boots is
    /// ignored by ArduPilot. (ArduCopter on the ground already says STANDBY while it
    /// initialises, so `set_mode` also checks HEARTBEAT and asks again.)
    pub async fn ready(&self) -> Result<(), Failure> {
        use mavlink::dialects::ardupilotmega::MavState::{
            MAV_STATE_ACTIVE, MAV_STATE_CRITICAL, MAV_STATE_STANDBY,
        };
        self.wait_for(
            self.tuning.ready_timeout,
            "waiting for the autopilot to be ready (MAV_STATE_STANDBY)",
            |c| {
                matches!(
                    c.v.seen().status,
                    Some(MAV_STATE_STANDBY | MAV_STATE_ACTIVE | MAV_STATE_CRITICAL)
                )
            },
        )
        .await
    }

    /// Switches to `mode` and waits until HEARTBEAT shows it, asking again if it does not.
    pub async fn set_mode(&self, want: Mode) -> Result<(), Failure> {
        let flavour = self.v.flavour();
        let Some((p2, p3)) = mode::set_mode_params(flavour, want) else {
            return Err(failed(format!("{}: no such mode", self.name)));
        };
        self.v.seen().expected = Some(want);
        let is = |c: &Craft| mode::classify(flavour, c.v.seen().custom_mode) == want;
        for _ in 0..self.tuning.command_tries {
            if is(self) {
                return Ok(());
            }
            let custom = MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED.bits() as f32;
            self.command(MavCmd::MAV_CMD_DO_SET_MODE, [custom, p2, p3, 0.0, 0.0, 0.0, 0.0]).await?;
            if self.wait_for(Duration::from_secs(3), "", is).await.is_ok() {
                return Ok(());
            }
        }
        Err(failed(format!(
            "{}: the autopilot accepted {want:?} mode but did not switch to it",
            self.name
        )))
    }

    /// Sets the ground speed (only when it changes: each is a command with an ACK).
    pub async fn speed(&self, speed: f64) -> Result<(), Failure> {
        if self.speed.lock().is_some_and(|s| (s - speed).abs() < 1e-6) {
            return Ok(());
        }
        self.command(
            MavCmd::MAV_CMD_DO_CHANGE_SPEED,
            [1.0, speed as f32, -1.0, 0.0, 0.0, 0.0, 0.0],
        )
        .await?;
        *self.speed.lock() = Some(speed);
        Ok(())
    }

    /// Sends a position target (local metres, z above home). ArduPilot takes
    /// SET_POSITION_TARGET_GLOBAL_INT in GUIDED; PX4 takes DO_REPOSITION in HOLD.
    pub async fn target(&self, to: [f64; 3]) -> Result<(), Failure> {
        let (lat, lon) = self.v.origin().to_e7(to[0], to[1]);
        match self.v.flavour() {
            Flavour::Px4 => {
                // PX4's navigator reads DO_REPOSITION's altitude above mean sea level,
                // whatever frame it comes in: a height above home sent as such (12 m,
                // relative frame) brought a PX4 SITL copter down to land. So it is sent
                // above sea level, from the vehicle's own home, in the frame that says so.
                let Some(home) = self.fix().map(|f| f.home_amsl) else {
                    return Err(failed(format!("{} has reported no position yet", self.name)));
                };
                // param1: the ground speed last set (-1: PX4's cruise speed); bit 0 of
                // param2: switch to HOLD, where a reposition is flown.
                let speed = self.speed.lock().map_or(-1.0, |s| s as f32);
                self.set_targeted();
                self.command_int(
                    MavCmd::MAV_CMD_DO_REPOSITION,
                    MavFrame::MAV_FRAME_GLOBAL,
                    [speed, 1.0, 0.0, f32::NAN],
                    (lat, lon, (home + to[2]) as f32),
                )
                .await
            }
            Flavour::ArduPilot => {
                let ignore = PositionTargetTypemask::POSITION_TARGET_TYPEMASK_VX_IGNORE
                    | PositionTargetTypemask::POSITION_TARGET_TYPEMASK_VY_IGNORE
                    | PositionTargetTypemask::POSITION_TARGET_TYPEMASK_VZ_IGNORE
                    | PositionTargetTypemask::POSITION_TARGET_TYPEMASK_AX_IGNORE
                    | PositionTargetTypemask::POSITION_TARGET_TYPEMASK_AY_IGNORE
                    | PositionTargetTypemask::POSITION_TARGET_TYPEMASK_AZ_IGNORE
                    | PositionTargetTypemask::POSITION_TARGET_TYPEMASK_YAW_IGNORE
                    | PositionTargetTypemask::POSITION_TARGET_TYPEMASK_YAW_RATE_IGNORE;
                let msg = MavMessage::SET_POSITION_TARGET_GLOBAL_INT(
                    SET_POSITION_TARGET_GLOBAL_INT_DATA {
                        time_boot_ms: 0,
                        lat_int: lat,
                        lon_int: lon,
                        alt: to[2] as f32,
                        vx: 0.0,
                        vy: 0.0,
                        vz: 0.0,
                        afx: 0.0,
                        afy: 0.0,
                        afz: 0.0,
                        yaw: 0.0,
                        yaw_rate: 0.0,
                        type_mask: ignore,
                        target_system: self.v.system,
                        target_component: 1,
                        coordinate_frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
                    },
                );
                self.link.send(&msg).await;
                Ok(())
            }
        }
    }

    /// Notes that a target is about to be sent, for [`Craft::refused`].
    pub fn set_targeted(&self) {
        *self.targeted.lock() = Some(Instant::now());
    }

    /// Fails the call when the autopilot refused its last target in words only. PX4
    /// acknowledges DO_REPOSITION and DO_ORBIT (its commander) before its navigator looks
    /// at them, and the navigator refuses one in words alone (`crate::px4::refuses`):
    /// without this the drone would wait where it is until the call's time ran out.
    pub fn refused(&self) -> Result<(), Failure> {
        let Some(sent) = *self.targeted.lock() else { return Ok(()) };
        match self.v.words_since(sent).into_iter().find(|w| crate::px4::refuses(w)) {
            Some(words) => Err(failed(format!("{} refused where it was sent: {words}", self.name))),
            None => Ok(()),
        }
    }

    /// Holds where the drone is (for PAUSE and ABORT).
    pub async fn hold(&self) {
        if let Some(fix) = self.fix() {
            let _ = self.target(fix.pos).await;
        }
    }
}

/// The engine's PAUSE/RESUME for one call: `true` while paused.
pub type Paused = watch::Receiver<bool>;
