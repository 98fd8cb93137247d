//! What the backend knows of one vehicle: the last of each message it sent, the answers
//! commands wait for, and detection (a geometric sensor over the reported track).

use parking_lot::{Mutex, MutexGuard};
use std::collections::BTreeMap;

use aviary_api::geometry::dist_to_segment;
use aviary_api::trace::AutopilotAction;
use aviary_api::{BuiltinException, DroneEvent, DroneId, Failure};
use aviary_clock::Instant;
use aviary_world::Target;
use mavlink::dialects::ardupilotmega::{
    MavCmd, MavLandedState, MavMessage, MavMissionResult, MavMissionType, MavModeFlag,
    MavParamType, MavResult, MavState, MavSysStatusSensor, GLOBAL_POSITION_INT_DATA,
    HEARTBEAT_DATA,
};
use tokio::sync::{mpsc, oneshot};

use crate::battery::{self, Draw};
use crate::failsafe::{failsafe, FAILSAFE_WAIT};
use crate::mode::{self, Flavour, Mode};
use crate::plausible;
use crate::words::Words;
use aviary_api::geo::Origin;

/// The last fix a vehicle reported, in the local frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fix {
    pub pos: [f64; 3],
    /// Ground speed, m/s.
    pub speed: f64,
    /// Degrees clockwise from north.
    pub heading: f64,
    /// Metres above sea level of the vehicle's home (its `alt` less its `relative_alt`).
    pub home_amsl: f64,
}

/// One activation of `StartDetection(kind)`: which world targets it has found.
pub struct Activation {
    pub kind: String,
    pub range: f64,
    pub found: Vec<bool>,
}

#[derive(Default)]
pub struct Seen {
    /// The last HEARTBEAT, by the mission's clock and by the wall's.
    pub heartbeat: Option<Instant>,
    pub heartbeat_wall: Option<std::time::Instant>,
    /// Its own clock, for the run's pace (`clock`).
    pub clock: Option<crate::clock::Heard>,
    pub flavour: Option<Flavour>,
    pub custom_mode: u32,
    pub armed: bool,
    pub status: Option<MavState>,
    pub fix: Option<Fix>,
    /// The vehicle's home (HOME_POSITION) in the local frame, height above the origin.
    pub home: Option<[f64; 3]>,
    /// Fraction of a full battery, when the vehicle reports one.
    pub battery: Option<f64>,
    /// Whether SYS_STATUS or BATTERY_STATUS came (a vehicle may report no charge in them).
    pub battery_reported: bool,
    /// The current it draws in the air, for the battery rule.
    pub draw: Draw,
    /// Answers to the facts' PARAM_REQUEST_READs, as sent (value, type), by name.
    pub params: BTreeMap<String, (f32, MavParamType)>,
    pub landed: Option<MavLandedState>,
    /// Recent STATUSTEXTs (the autopilot's reasons), newest last.
    pub words: Words,
    /// The mode this backend last asked for; another RTL or LAND is the autopilot's own.
    pub expected: Option<Mode>,
    /// A failsafe mode change not yet named: when it was seen, the mode's name and what
    /// it does.
    failsafe: Option<(Instant, String, Mode)>,
    /// What the vehicle reports of itself, for naming a failsafe: the battery's charge
    /// state is LOW or worse, its fence is breached, its GPS has no 3D fix.
    battery_failing: bool,
    fence_unhealthy: bool,
    fence_breached: bool,
    no_gps: bool,
    pub detecting: Vec<Activation>,
    /// Metres flown and seconds in the air while armed, from the reported track.
    pub odometer: f64,
    pub flight_time: f64,
    fix_at: Option<Instant>,
    /// The vehicle's own clock (`time_boot_ms`) at that fix: a SITL or `aviary vehicles`
    /// running faster than real time flies farther per wall-clock second than any drone.
    fix_boot_ms: u32,
    /// Since when the positions reported have been ones the vehicle could not have
    /// reached (`plausible`), and whether that was raised as `PositionLost`.
    /// When positions began to jump: the wall clock and the vehicle's (`time_boot_ms`).
    doubted_since: Option<(Instant, u32)>,
    doubt_raised: bool,
    acks: Vec<(MavCmd, oneshot::Sender<MavResult>)>,
    /// The last command the vehicle said was in progress (COMMAND_ACK IN_PROGRESS), and when.
    in_progress: Option<(MavCmd, Instant)>,
    /// Where an upload in progress hears the vehicle's requests and its answer.
    pub upload: Option<mpsc::UnboundedSender<Upload>>,
    /// The mission item the vehicle flies to (MISSION_CURRENT) and the last one it reached
    /// (MISSION_ITEM_REACHED), until the next upload clears them.
    pub mission_current: Option<u16>,
    pub mission_reached: Option<u16>,
}

/// What a vehicle says during a mission upload.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Upload {
    /// MISSION_REQUEST_INT or MISSION_REQUEST: send item `seq`.
    Request(u16),
    /// MISSION_ACK: the upload's end.
    Ack(MavMissionResult),
}

impl Seen {
    /// SYS_STATUS or BATTERY_STATUS: the charge left and the current drawn.
    fn take_battery(&mut self, now: Instant, remaining: i8, centiamps: i16) {
        self.battery_reported = true;
        // -1 is "unknown", and no battery holds more than 100 %: the last
        // believable charge stands.
        if let Some(charge) = plausible::charge(remaining) {
            self.battery = Some(charge);
        }
        let airborne = self.armed && self.fix.is_some_and(|f| f.pos[2] > AIRBORNE_ABOVE);
        self.draw.record(now, battery::amps(centiamps), airborne);
    }

    /// A mission message to the upload in progress, if one is.
    fn tell_upload(&mut self, what: Upload) {
        if let Some(tx) = &self.upload {
            let _ = tx.send(what);
        }
    }

    /// COMMAND_ACK: the answer goes to the first one waiting for it.
    fn answer(&mut self, command: MavCmd, result: MavResult) {
        if let Some(i) = self.acks.iter().position(|(c, tx)| *c == command && !tx.is_closed()) {
            let (_, tx) = self.acks.remove(i);
            let _ = tx.send(result);
        }
        self.acks.retain(|(_, tx)| !tx.is_closed());
    }
}

/// Whether a vehicle's state says it is going down, or gone.
fn going_down(s: Option<MavState>) -> bool {
    matches!(
        s,
        Some(
            MavState::MAV_STATE_EMERGENCY
                | MavState::MAV_STATE_FLIGHT_TERMINATION
                | MavState::MAV_STATE_POWEROFF
        )
    )
}

/// A vehicle of a link, by its MAVLink system id.
pub struct Vehicle {
    pub drone: DroneId,
    pub name: String,
    pub system: u8,
    origin: Origin,
    targets: Vec<Target>,
    seen: Mutex<Seen>,
    events: mpsc::UnboundedSender<DroneEvent>,
    alarms: mpsc::UnboundedSender<(DroneId, Failure)>,
}

const MISSION: MavMissionType = MavMissionType::MAV_MISSION_TYPE_MISSION;

/// Armed and this high (m): in the air, for the flight time and the measured draw.
const AIRBORNE_ABOVE: f64 = 0.3;

impl Vehicle {
    pub fn new(
        drone: DroneId,
        name: String,
        system: u8,
        origin: Origin,
        targets: Vec<Target>,
        events: mpsc::UnboundedSender<DroneEvent>,
        alarms: mpsc::UnboundedSender<(DroneId, Failure)>,
    ) -> Vehicle {
        Vehicle {
            drone,
            name,
            system,
            origin,
            targets,
            seen: Mutex::new(Seen::default()),
            events,
            alarms,
        }
    }

    pub fn seen(&self) -> MutexGuard<'_, Seen> {
        self.seen.lock()
    }

    pub fn origin(&self) -> Origin {
        self.origin
    }

    pub fn flavour(&self) -> Flavour {
        self.seen().flavour.unwrap_or(Flavour::ArduPilot)
    }

    /// Waits for the COMMAND_ACK of `command`; register before sending.
    /// Whether the vehicle has said, since `since`, that `command` is in progress (PX4's
    /// gripper does, until it has opened or closed).
    pub fn in_progress(&self, command: MavCmd, since: Instant) -> bool {
        self.seen().in_progress.is_some_and(|(c, at)| c == command && at >= since)
    }

    pub fn expect_ack(&self, command: MavCmd) -> oneshot::Receiver<MavResult> {
        let (tx, rx) = oneshot::channel();
        self.seen().acks.push((command, tx));
        rx
    }

    /// STATUSTEXTs received since `since`, joined: the autopilot's reason for a refusal.
    pub fn texts_since(&self, since: Instant) -> Option<String> {
        let texts = self.words_since(since);
        (!texts.is_empty()).then(|| texts.join("; "))
    }

    /// The texts received since `since`, oldest first.
    pub fn words_since(&self, since: Instant) -> Vec<String> {
        self.seen().words.since(since)
    }

    /// Takes in one message from this vehicle's autopilot.
    pub fn observe(&self, msg: &MavMessage) {
        let now = Instant::now();
        let mut seen = self.seen();
        match msg {
            MavMessage::HEARTBEAT(hb) => self.take_heartbeat(&mut seen, now, hb),
            // ArduPilot sends 0°N 0°E until its EKF has an origin: that is no position.
            MavMessage::GLOBAL_POSITION_INT(p) if p.lat == 0 && p.lon == 0 => {}
            MavMessage::HOME_POSITION(h) if h.latitude != 0 || h.longitude != 0 => {
                let xy = self.origin.from_e7(h.latitude, h.longitude);
                seen.home = Some([xy[0], xy[1], f64::from(h.altitude) / 1000.0 - self.origin.alt]);
            }
            MavMessage::GLOBAL_POSITION_INT(p) => {
                seen.clock = Some(crate::clock::Heard::take(
                    seen.clock,
                    p.time_boot_ms,
                    std::time::Instant::now(),
                ));
                self.take_position(&mut seen, now, p);
            }
            MavMessage::SYS_STATUS(s) => {
                seen.take_battery(now, s.battery_remaining, s.current_battery);
                // A sensor the vehicle has and uses but calls unhealthy (ArduPilot clears
                // the battery's bit with its battery failsafe, the fence's on a breach).
                let failing = |bit: MavSysStatusSensor| {
                    s.onboard_control_sensors_enabled.contains(bit)
                        && !s.onboard_control_sensors_health.contains(bit)
                };
                seen.battery_failing = failing(MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_BATTERY);
                seen.fence_unhealthy = failing(MavSysStatusSensor::MAV_SYS_STATUS_GEOFENCE);
            }
            MavMessage::BATTERY_STATUS(b) if b.id == 0 => {
                seen.take_battery(now, b.battery_remaining, b.current_battery);
            }
            MavMessage::PARAM_VALUE(p) => {
                let name = p.param_id.to_str().unwrap_or("").trim_end_matches('\0');
                if crate::facts::wanted(name) {
                    seen.params.insert(name.to_owned(), (p.param_value, p.param_type));
                }
            }
            MavMessage::EXTENDED_SYS_STATE(e) => seen.landed = Some(e.landed_state),
            MavMessage::FENCE_STATUS(f) => seen.fence_breached = f.breach_status != 0,
            MavMessage::GPS_RAW_INT(g) => {
                seen.no_gps = (g.fix_type as u8) < 3;
            }
            MavMessage::STATUSTEXT(t) => {
                seen.words.take(now, t.id, t.chunk_seq, &t.text[..]);
            }
            MavMessage::MISSION_REQUEST_INT(r) if r.mission_type == MISSION => {
                seen.tell_upload(Upload::Request(r.seq));
            }
            #[allow(deprecated)] // PX4 asks with it until it hears MISSION_ITEM_INT.
            MavMessage::MISSION_REQUEST(r) if r.mission_type == MISSION => {
                seen.tell_upload(Upload::Request(r.seq));
            }
            MavMessage::MISSION_ACK(a) if a.mission_type == MISSION => {
                seen.tell_upload(Upload::Ack(a.mavtype));
            }
            MavMessage::MISSION_CURRENT(m) => seen.mission_current = Some(m.seq),
            MavMessage::MISSION_ITEM_REACHED(m) => seen.mission_reached = Some(m.seq),
            MavMessage::COMMAND_ACK(ack) if ack.result == MavResult::MAV_RESULT_IN_PROGRESS => {
                seen.in_progress = Some((ack.command, now));
            }
            MavMessage::COMMAND_ACK(ack) => {
                seen.answer(ack.command, ack.result);
            }
            _ => {}
        }
        self.name_failsafe(&mut seen, now);
    }

    /// HEARTBEAT: the autopilot, its mode, armed, its state; an alarm when the vehicle
    /// says it is going down, and a failsafe noted when it changes mode by itself.
    fn take_heartbeat(&self, seen: &mut Seen, now: Instant, hb: &HEARTBEAT_DATA) {
        let flavour = Flavour::of(hb.autopilot);
        let before = seen.heartbeat.map(|_| mode::classify(flavour, seen.custom_mode));
        seen.heartbeat = Some(now);
        seen.heartbeat_wall = Some(std::time::Instant::now());
        seen.flavour = Some(flavour);
        seen.custom_mode = hb.custom_mode;
        seen.armed = hb.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED);
        let was = seen.status.replace(hb.system_status);
        if going_down(Some(hb.system_status)) && !going_down(was) {
            // The vehicle says it is going down (or gone): it is lost to the mission.
            let why = seen.words.last().unwrap_or_else(|| "no reason given".to_owned());
            let reason =
                format!("{}: the autopilot reports {:?} ({why})", self.name, hb.system_status);
            let _ =
                self.alarms.send((self.drone, Failure::new(BuiltinException::DroneLost, reason)));
        }
        let after = mode::classify(flavour, hb.custom_mode);
        let changed = before.is_some_and(|b| b != after);
        if changed && matches!(after, Mode::Rtl | Mode::Land) && seen.expected != Some(after) {
            // The autopilot changed mode by itself: a failsafe. Its reason may
            // come just after the HEARTBEAT (ArduCopter queues its STATUSTEXT),
            // so it is named once the vehicle has said why, or after a moment.
            seen.expected = Some(after);
            seen.failsafe = Some((now, mode::name(flavour, hb.custom_mode), after));
        }
    }

    /// GLOBAL_POSITION_INT: the fix, the odometer and detection, unless the vehicle could
    /// not have got there.
    fn take_position(&self, seen: &mut Seen, now: Instant, p: &GLOBAL_POSITION_INT_DATA) {
        let xy = self.origin.from_e7(p.lat, p.lon);
        let fix = Fix {
            pos: [xy[0], xy[1], f64::from(p.relative_alt) / 1000.0],
            speed: f64::from(p.vx).hypot(f64::from(p.vy)) / 100.0,
            heading: if p.hdg == u16::MAX { 0.0 } else { f64::from(p.hdg) / 100.0 },
            home_amsl: (f64::from(p.alt) - f64::from(p.relative_alt)) / 1000.0,
        };
        // Seconds since the last believed position, by the vehicle's clock when it keeps one.
        let dt = seen.fix_at.map(|at| {
            plausible::elapsed(
                seen.fix_boot_ms,
                p.time_boot_ms,
                now.duration_since(at).as_secs_f64(),
            )
        });
        if let (Some(before), Some(dt)) = (seen.fix, dt) {
            if !plausible::reachable(before.pos, fix.pos, dt) {
                self.doubt(seen, now, p.time_boot_ms, before.pos, fix.pos, dt);
                return;
            }
        }
        seen.doubted_since = None;
        seen.doubt_raised = false;
        let from = seen.fix.map_or(xy, |f| [f.pos[0], f.pos[1]]);
        if let (Some(before), Some(dt), true) = (seen.fix, dt, seen.armed) {
            let d: f64 = (0..3).map(|k| (fix.pos[k] - before.pos[k]).powi(2)).sum();
            seen.odometer += d.sqrt();
            if before.pos[2] > AIRBORNE_ABOVE {
                seen.flight_time += dt;
            }
        }
        seen.fix_at = Some(now);
        seen.fix_boot_ms = p.time_boot_ms;
        seen.fix = Some(fix);
        self.scan(seen, from, xy);
    }

    /// A position the vehicle could not have reached: not taken. Once such positions have
    /// come for [`plausible::DOUBT_FOR`] (by the vehicle's clock when it keeps one), the
    /// drone has lost its position (`PositionLost`).
    fn doubt(
        &self,
        seen: &mut Seen,
        now: Instant,
        boot_ms: u32,
        before: [f64; 3],
        after: [f64; 3],
        dt: f64,
    ) {
        let (since, since_boot_ms) = *seen.doubted_since.get_or_insert((now, boot_ms));
        let doubted_for =
            plausible::elapsed(since_boot_ms, boot_ms, now.duration_since(since).as_secs_f64());
        if seen.doubt_raised || doubted_for < plausible::DOUBT_FOR.as_secs_f64() {
            return;
        }
        seen.doubt_raised = true;
        let jump = (0..3).map(|k| (after[k] - before[k]).powi(2)).sum::<f64>().sqrt();
        let reason = format!(
            "{}: its reported position jumps {} in {:.1} s, farther than any drone flies: not believed",
            self.name,
            if jump >= 1000.0 { format!("{:.0} km", jump / 1000.0) } else { format!("{jump:.0} m") },
            dt
        );
        let _ =
            self.alarms.send((self.drone, Failure::new(BuiltinException::PositionLost, reason)));
    }

    /// Names a pending failsafe once the vehicle's state or words say what it was, or
    /// after [`FAILSAFE_WAIT`] with what is known then.
    fn name_failsafe(&self, seen: &mut Seen, now: Instant) {
        let Some((at, mode, does)) = seen.failsafe.clone() else { return };
        // The reason is said before the mode changes: by ArduPilot at once, by PX4 when its
        // failsafe starts, which then holds for COM_FAIL_ACT_T (5 s by default, on the
        // vehicle's clock, which is the mission's) before it acts.
        let look_back = match seen.flavour {
            Some(Flavour::Px4) => std::time::Duration::from_secs(10),
            _ => std::time::Duration::from_secs(3),
        };
        // At most `look_back` before, and never before the run's clock began (it starts at
        // zero: the subtraction stops there).
        let why = seen.words.since(at - look_back);
        let state = if seen.battery_failing {
            Some(BuiltinException::BatteryCritical)
        } else if seen.fence_unhealthy || seen.fence_breached {
            Some(BuiltinException::GeofenceViolation)
        } else if seen.no_gps {
            Some(BuiltinException::PositionLost)
        } else {
            None
        };
        let failure = failsafe(&self.name, &mode, &why.join("; "), state);
        if failure.exception == BuiltinException::CommandFailed
            && now.duration_since(at) < FAILSAFE_WAIT
        {
            return;
        }
        seen.failsafe = None;
        // What the autopilot does is recorded as it is said (`autopilot`), before the fault
        // it stands for reaches the engine through the backend.
        let action =
            if does == Mode::Land { AutopilotAction::Land } else { AutopilotAction::ReturnHome };
        let reason = failure.reason.clone();
        let _ = self.events.send(DroneEvent::Autopilot { drone: self.drone, action, reason });
        let _ = self.alarms.send((self.drone, failure));
    }

    /// Detection: each world target of an active kind within range of the ground track
    /// flown between two fixes is found once per activation (as the simulator does).
    fn scan(&self, seen: &mut Seen, from: [f64; 2], to: [f64; 2]) {
        for act in &mut seen.detecting {
            for (i, target) in self.targets.iter().enumerate() {
                if act.found[i] || target.kind != act.kind {
                    continue;
                }
                let at = [target.at[0], target.at[1]];
                if dist_to_segment(at, from, to) <= act.range {
                    act.found[i] = true;
                    let _ = self.events.send(DroneEvent::Detected {
                        drone: self.drone,
                        kind: act.kind.clone(),
                        location: [at[0], at[1], 0.0],
                    });
                }
            }
        }
    }

    pub fn target_count(&self) -> usize {
        self.targets.len()
    }
}
