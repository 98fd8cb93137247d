//! The mission protocol as PX4's MavlinkMissionManager (mavlink_mission.cpp) speaks it,
//! for one vehicle: an upload (MISSION_COUNT, then a MISSION_REQUEST for each item and
//! the MISSION_ACK), a download (MISSION_REQUEST_LIST), MISSION_CLEAR_ALL and
//! MISSION_SET_CURRENT, with PX4's refusals and words, and its progress messages:
//! MISSION_CURRENT (on a change, and at 1 Hz as a stream) and MISSION_ITEM_REACHED.
//!
//! Like PX4, the vehicle asks for items with MISSION_REQUEST (floats) until a client shows
//! it speaks MISSION_REQUEST_INT or MISSION_ITEM_INT, or answers a request with
//! MAV_MISSION_UNSUPPORTED (as MAVSDK does), when it switches (its `_int_mode`). Items are
//! checked as PX4's parse_mavlink_mission_item checks them (their frame, their command);
//! a transfer that hears nothing for 5 s of simulated time ends with "Operation timeout".
//! Only missions are kept: a fence or rally upload is UNSUPPORTED (none is simulated),
//! and a download of either has no items.

// MISSION_ITEM and MISSION_REQUEST, which PX4 still speaks.
#![allow(deprecated)]

use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavCmd, MavFrame, MavMessage, MavMissionResult, MavMissionType, MavSeverity, MISSION_ACK_DATA,
    MISSION_COUNT_DATA, MISSION_CURRENT_DATA, MISSION_ITEM_DATA, MISSION_ITEM_INT_DATA,
    MISSION_REQUEST_DATA, MISSION_REQUEST_INT_DATA,
};

use super::Nav;
use crate::autopilot::{Autopilot, Out, Reply};

use MavMissionResult::*;
use MavSeverity::{MAV_SEVERITY_CRITICAL as CRITICAL, MAV_SEVERITY_INFO as INFO};

/// MAVLINK_MISSION_PROTOCOL_TIMEOUT_DEFAULT, s.
const TIMEOUT: f64 = 5.0;
/// The most items PX4 SITL keeps (NUM_MISSIONS_SUPPORTED on POSIX).
const MAX_ITEMS: u16 = u16::MAX - 1;

/// A mission item as uploaded (a float item's latitude and longitude as degrees × 10⁷).
#[derive(Clone, Debug)]
pub(crate) struct Item {
    pub frame: u8,
    pub mav_frame: MavFrame,
    pub command: MavCmd,
    pub current: u8,
    pub autocontinue: u8,
    pub p: [f32; 4],
    pub x: i32,
    pub y: i32,
    pub z: f32,
}

#[derive(Clone, Debug, Default)]
pub(crate) enum Transfer {
    #[default]
    Idle,
    /// An upload from `partner`: `next` is the item asked for.
    Getting { partner: (u8, u8), count: u16, next: u16, items: Vec<Item>, since: f64 },
    /// A download to `partner`: `next` is the item it may ask for next.
    Sending { partner: (u8, u8), kind: MavMissionType, count: u16, next: u16, since: f64 },
}

/// A vehicle's mission, its progress and its transfer.
#[derive(Clone, Debug, Default)]
pub(crate) struct Mission {
    pub items: Vec<Item>,
    /// The mission's id (MISSION_ACK's and MISSION_COUNT's opaque_id): a hash of its items.
    pub id: u32,
    pub current: u16,
    pub reached: Option<u16>,
    pub finished: bool,
    pub int_mode: bool,
    pub transfer: Transfer,
    /// After the last upload: the seq the next duplicate of its last item repeats.
    pub last_got: Option<u16>,
}

impl Mission {
    /// A mission to fly (PX4 checks more; the items were checked as they came).
    pub fn valid(&self) -> bool {
        !self.items.is_empty()
    }
}

/// MAV_CMD numbers PX4 takes in a global frame, and in MAV_FRAME_MISSION
/// (parse_mavlink_mission_item).
const GLOBAL_COMMANDS: &[u32] = &[
    16, 17, 19, 21, 22,
    31, // waypoint, loiter unlimited and time, land, take-off, loiter to alt
    80, 201, 195, // ROI, SET_ROI (as locations), SET_ROI_LOCATION
    84, 85, 4501, // VTOL take-off and land, condition gate
    5000, 5001, 5002, 5003, 5004, 5100, // fence and rally points
];
const MISSION_COMMANDS: &[u32] = &[
    177, 80, 201, 42600, 211, // jump, ROI, SET_ROI, winch, gripper
    178, 179, 189, 2003, 203, 204, 205, 1000, 532,
    1001, // speed, home, land start, camera, mount, gimbal
    2000, 2001, 2500, 2501, 200, 206, 260, 214, 530,
    534, // capture, video, triggers, camera mode
    3000, 93, 20, 196, 197, 112, 114,
    187, // VTOL transition, delay, RTL, ROI, conditions, actuator
];
/// Fence and rally commands: no mission item.
const NOT_MISSION: &[u32] = &[5001, 5002, 5003, 5004, 5100];

/// Whether PX4 takes the item (its frame and command), else the MISSION_ACK's result.
fn check(frame: u8, command: u32, int_mode: bool) -> Result<(), MavMissionResult> {
    let global = matches!(frame, 0 | 3) || (int_mode && matches!(frame, 5 | 6));
    if global {
        if GLOBAL_COMMANDS.contains(&command) {
            Ok(())
        } else {
            Err(MAV_MISSION_UNSUPPORTED)
        }
    } else if frame == 2 {
        if MISSION_COMMANDS.contains(&command) {
            Ok(())
        } else {
            Err(MAV_MISSION_UNSUPPORTED)
        }
    } else {
        Err(MAV_MISSION_UNSUPPORTED_FRAME)
    }
}

/// The mission's id: FNV-1a over its items.
fn mission_id(items: &[Item]) -> u32 {
    let mut h: u32 = 0x811c_9dc5;
    let mut eat = |bytes: &[u8]| {
        for b in bytes {
            h = (h ^ u32::from(*b)).wrapping_mul(0x0100_0193);
        }
    };
    for it in items {
        eat(&[it.frame, it.current, it.autocontinue]);
        eat(&(it.command as u32).to_le_bytes());
        for p in it.p {
            eat(&p.to_bits().to_le_bytes());
        }
        eat(&it.x.to_le_bytes());
        eat(&it.y.to_le_bytes());
        eat(&it.z.to_bits().to_le_bytes());
    }
    h
}

/// The fields of MISSION_ITEM and MISSION_ITEM_INT alike.
pub(crate) struct Incoming {
    pub seq: u16,
    pub kind: MavMissionType,
    pub item: Item,
    pub int: bool,
}

impl Incoming {
    pub fn of_int(m: &MISSION_ITEM_INT_DATA) -> Incoming {
        Incoming {
            seq: m.seq,
            kind: m.mission_type,
            int: true,
            item: Item {
                frame: m.frame as u8,
                mav_frame: m.frame,
                command: m.command,
                current: m.current,
                autocontinue: m.autocontinue,
                p: [m.param1, m.param2, m.param3, m.param4],
                x: m.x,
                y: m.y,
                z: m.z,
            },
        }
    }

    pub fn of_float(m: &MISSION_ITEM_DATA) -> Incoming {
        let e7 = |v: f32| (f64::from(v) * 1e7).round() as i32;
        Incoming {
            seq: m.seq,
            kind: m.mission_type,
            int: false,
            item: Item {
                frame: m.frame as u8,
                mav_frame: m.frame,
                command: m.command,
                current: m.current,
                autocontinue: m.autocontinue,
                p: [m.param1, m.param2, m.param3, m.param4],
                x: e7(m.x),
                y: e7(m.y),
                z: m.z,
            },
        }
    }
}

/// Whether a mission message is for vehicle `system` (CHECK_SYSID_COMPID_MISSION): its
/// system exactly, the autopilot, the mission planner or any component.
pub(crate) fn for_me(system: u8, target: (u8, u8)) -> bool {
    target.0 == system && matches!(target.1, 0 | 1 | 190)
}

impl Autopilot {
    fn ack_to(
        &self,
        i: usize,
        to: (u8, u8),
        result: MavMissionResult,
        kind: MavMissionType,
        id: u32,
    ) -> Reply {
        Reply::asker(
            self.copters[i].system,
            MavMessage::MISSION_ACK(MISSION_ACK_DATA {
                target_system: to.0,
                target_component: to.1,
                mavtype: result,
                mission_type: kind,
                opaque_id: id,
            }),
        )
    }

    fn critical(&self, i: usize, text: &str) -> Vec<Reply> {
        self.say(i, CRITICAL, text).into_iter().map(Reply::all).collect()
    }

    fn request(&self, i: usize, to: (u8, u8), seq: u16) -> Reply {
        let system = self.copters[i].system;
        let kind = MavMissionType::MAV_MISSION_TYPE_MISSION;
        let msg = if self.px4(i).mission.int_mode {
            MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
                seq,
                target_system: to.0,
                target_component: to.1,
                mission_type: kind,
            })
        } else {
            #[allow(deprecated)]
            MavMessage::MISSION_REQUEST(MISSION_REQUEST_DATA {
                seq,
                target_system: to.0,
                target_component: to.1,
                mission_type: kind,
            })
        };
        Reply::asker(system, msg)
    }

    /// MISSION_CURRENT: the current item, the count (65535 with no mission) and the ids.
    pub(crate) fn px4_mission_current(&self, i: usize) -> MavMessage {
        let m = &self.px4(i).mission;
        MavMessage::MISSION_CURRENT(MISSION_CURRENT_DATA {
            seq: m.current,
            total: if m.items.is_empty() { u16::MAX } else { m.items.len() as u16 },
            mission_id: m.id,
            ..MISSION_CURRENT_DATA::default()
        })
    }

    /// MISSION_COUNT from `from`: an upload starts (0 items: the mission is cleared).
    pub(crate) fn px4_mission_count(
        &mut self,
        i: usize,
        from: (u8, u8),
        count: u16,
        kind: MavMissionType,
    ) -> Vec<Reply> {
        let now = self.fleet.time();
        let mission = MavMissionType::MAV_MISSION_TYPE_MISSION;
        match self.px4(i).mission.transfer.clone() {
            super::mission::Transfer::Idle => {}
            super::mission::Transfer::Getting { partner, next, .. } => {
                if from != partner {
                    return vec![self.ack_to(i, from, MAV_MISSION_ERROR, kind, 0)];
                }
                if next == 0 {
                    // Its MISSION_REQUEST was lost: again.
                    if let super::mission::Transfer::Getting { since, .. } =
                        &mut self.px4_mut(i).mission.transfer
                    {
                        *since = now;
                    }
                    return vec![self.request(i, partner, 0)];
                }
                let mut out = self.critical(i, "WPM: REJ. CMD: Busy\t");
                out.push(self.ack_to(i, partner, MAV_MISSION_ERROR, kind, 0));
                return out;
            }
            super::mission::Transfer::Sending { .. } => {
                let mut out = self.critical(i, "WPM: IGN MISSION_COUNT: Busy\t");
                out.push(self.ack_to(i, from, MAV_MISSION_ERROR, kind, 0));
                return out;
            }
        }
        if kind != mission {
            // Fences and rally points are not simulated: none is kept.
            let result = if count == 0 { MAV_MISSION_ACCEPTED } else { MAV_MISSION_UNSUPPORTED };
            return vec![self.ack_to(i, from, result, kind, 0)];
        }
        if count > MAX_ITEMS {
            return vec![self.ack_to(i, from, MAV_MISSION_NO_SPACE, kind, 0)];
        }
        if count == 0 {
            let mut out = self.px4_new_mission(i, Vec::new());
            out.push(self.ack_to(i, from, MAV_MISSION_ACCEPTED, kind, 0));
            return out;
        }
        self.px4_mut(i).mission.transfer =
            Transfer::Getting { partner: from, count, next: 0, items: Vec::new(), since: now };
        vec![self.request(i, from, 0)]
    }

    /// MISSION_ITEM or MISSION_ITEM_INT from `from`.
    pub(crate) fn px4_mission_item(&mut self, i: usize, from: (u8, u8), m: Incoming) -> Vec<Reply> {
        let now = self.fleet.time();
        self.px4_mut(i).mission.int_mode = m.int;
        let kind = MavMissionType::MAV_MISSION_TYPE_MISSION;
        let mut transfer = std::mem::take(&mut self.px4_mut(i).mission.transfer);
        let out = match &mut transfer {
            Transfer::Getting { partner, .. } if *partner != from => {
                self.critical(i, "REJ. MIS ITEM: partner id mismatch\t")
            }
            Transfer::Getting { .. } if m.kind != kind => {
                vec![self.ack_to(i, from, MAV_MISSION_ERROR, kind, 0)]
            }
            Transfer::Getting { count, next, items, since, .. } => {
                *since = now;
                if m.seq != *next {
                    // Not the one asked for: ignored.
                    Vec::new()
                } else if let Err(result) = check(m.item.frame, m.item.command as u32, m.int)
                    .and_then(|()| {
                        if NOT_MISSION.contains(&(m.item.command as u32)) {
                            Err(MAV_MISSION_ERROR)
                        } else {
                            Ok(())
                        }
                    })
                {
                    let mut out = Vec::new();
                    if result != MAV_MISSION_ERROR {
                        out.extend(self.critical(i, "IGN MISSION_ITEM: Invalid item\t"));
                    }
                    out.push(self.ack_to(i, from, result, kind, 0));
                    transfer = Transfer::Idle;
                    out
                } else {
                    items.push(m.item);
                    *next += 1;
                    if *next == *count {
                        let items = std::mem::take(items);
                        transfer = Transfer::Idle;
                        self.px4_mut(i).mission.last_got = Some(m.seq);
                        let mut out = self.px4_new_mission(i, items);
                        let id = self.px4(i).mission.id;
                        out.push(self.ack_to(i, from, MAV_MISSION_ACCEPTED, kind, id));
                        out
                    } else {
                        vec![self.request(i, from, *next)]
                    }
                }
            }
            Transfer::Idle => {
                if self.px4(i).mission.last_got == Some(m.seq) {
                    // The last item again: the client missed the ACK.
                    let id = self.px4(i).mission.id;
                    vec![self.ack_to(i, from, MAV_MISSION_ACCEPTED, kind, id)]
                } else {
                    let mut out = self.critical(i, "IGN MISSION_ITEM: No transfer\t");
                    out.push(self.ack_to(i, from, MAV_MISSION_ERROR, kind, 0));
                    out
                }
            }
            Transfer::Sending { .. } => {
                let mut out = self.critical(i, "IGN MISSION_ITEM: Busy\t");
                out.push(self.ack_to(i, from, MAV_MISSION_ERROR, kind, 0));
                out
            }
        };
        self.px4_mut(i).mission.transfer = transfer;
        out
    }

    /// The uploaded mission becomes the vehicle's (update_active_mission): its current
    /// item the one marked current, else the first. A mission flown now goes on with the
    /// new one; without items Mission mode has nothing to fly and holds.
    fn px4_new_mission(&mut self, i: usize, items: Vec<Item>) -> Vec<Reply> {
        let id = mission_id(&items);
        let current = items.iter().position(|it| it.current != 0).unwrap_or(0) as u16;
        let m = &mut self.px4_mut(i).mission;
        m.items = items;
        m.id = id;
        m.current = current;
        m.reached = None;
        m.finished = false;
        let system = self.copters[i].system;
        let mut out = vec![Reply::all(Out { system, msg: self.px4_mission_current(i).into() })];
        if self.px4(i).nav == Nav::Mission && self.copters[i].armed {
            let more = if self.px4(i).mission.valid() {
                self.px4_activate(i)
            } else {
                let mut said = self.say(i, CRITICAL, "No valid mission available, loitering\t");
                said.extend(self.px4_enter(i, Nav::Loiter));
                said
            };
            out.extend(more.into_iter().map(Reply::all));
        }
        out
    }

    /// MISSION_REQUEST_LIST from `from`: a download starts with MISSION_COUNT.
    pub(crate) fn px4_mission_list(
        &mut self,
        i: usize,
        from: (u8, u8),
        kind: MavMissionType,
    ) -> Vec<Reply> {
        let now = self.fleet.time();
        let busy = match &self.px4(i).mission.transfer {
            Transfer::Idle => false,
            Transfer::Sending { partner, kind: k, count, next, .. } => {
                // All sent: the ACK was lost, a new list may start.
                !(*next == *count || (*partner == from && *k == kind))
            }
            Transfer::Getting { .. } => true,
        };
        if busy {
            return self
                .say(i, INFO, "Mission download request ignored, already active\t")
                .into_iter()
                .map(Reply::all)
                .collect();
        }
        let count = if kind == MavMissionType::MAV_MISSION_TYPE_MISSION {
            self.px4(i).mission.items.len() as u16
        } else {
            0
        };
        let id = if count > 0 { self.px4(i).mission.id } else { 0 };
        self.px4_mut(i).mission.transfer =
            Transfer::Sending { partner: from, kind, count, next: 0, since: now };
        vec![Reply::asker(
            self.copters[i].system,
            MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
                count,
                target_system: from.0,
                target_component: from.1,
                mission_type: kind,
                opaque_id: id,
            }),
        )]
    }

    /// MISSION_REQUEST(_INT) from `from` during a download: the item, as an int item or
    /// a float one as it was asked.
    pub(crate) fn px4_mission_request(
        &mut self,
        i: usize,
        from: (u8, u8),
        seq: u16,
        kind: MavMissionType,
        int: bool,
    ) -> Vec<Reply> {
        let now = self.fleet.time();
        self.px4_mut(i).mission.int_mode = int;
        let mut transfer = std::mem::take(&mut self.px4_mut(i).mission.transfer);
        let out = match &mut transfer {
            Transfer::Sending { partner, .. } if *partner != from => {
                self.critical(i, "WPM: REJ. CMD: partner id mismatch\t")
            }
            Transfer::Sending { kind: k, .. } if *k != kind => Vec::new(),
            Transfer::Sending { count, next, since, kind: k, .. } => {
                *since = now;
                let ok = (seq == *next && *next < *count) || seq.checked_add(1) == Some(*next);
                if !ok || usize::from(seq) >= self.px4(i).mission.items.len() {
                    let k = *k;
                    transfer = Transfer::Idle;
                    let mut out = vec![self.ack_to(i, from, MAV_MISSION_ERROR, k, 0)];
                    out.extend(self.critical(i, "WPM: REJ. CMD: Req. WP was unexpected\t"));
                    out
                } else {
                    if seq == *next {
                        *next += 1;
                    }
                    vec![self.mission_item(i, from, seq, int)]
                }
            }
            // No transfer: ignored, as PX4 does for buggy clients.
            Transfer::Idle => Vec::new(),
            Transfer::Getting { .. } => self.critical(i, "WPM: REJ. CMD: Busy\t"),
        };
        self.px4_mut(i).mission.transfer = transfer;
        out
    }

    fn mission_item(&self, i: usize, to: (u8, u8), seq: u16, int: bool) -> Reply {
        let system = self.copters[i].system;
        let it = &self.px4(i).mission.items[usize::from(seq)];
        let kind = MavMissionType::MAV_MISSION_TYPE_MISSION;
        let msg = if int {
            MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
                param1: it.p[0],
                param2: it.p[1],
                param3: it.p[2],
                param4: it.p[3],
                x: it.x,
                y: it.y,
                z: it.z,
                seq,
                command: it.command,
                target_system: to.0,
                target_component: to.1,
                frame: it.mav_frame,
                current: u8::from(seq == self.px4(i).mission.current),
                autocontinue: it.autocontinue,
                mission_type: kind,
            })
        } else {
            #[allow(deprecated)]
            MavMessage::MISSION_ITEM(MISSION_ITEM_DATA {
                param1: it.p[0],
                param2: it.p[1],
                param3: it.p[2],
                param4: it.p[3],
                x: (f64::from(it.x) / 1e7) as f32,
                y: (f64::from(it.y) / 1e7) as f32,
                z: it.z,
                seq,
                command: it.command,
                target_system: to.0,
                target_component: to.1,
                frame: it.mav_frame,
                current: u8::from(seq == self.px4(i).mission.current),
                autocontinue: it.autocontinue,
                mission_type: kind,
            })
        };
        Reply::asker(system, msg)
    }

    /// MISSION_ACK from `from`: the end of a download, or an upload's MISSION_REQUEST
    /// refused (UNSUPPORTED: the client wants the other kind, int or float).
    pub(crate) fn px4_mission_ack(
        &mut self,
        i: usize,
        from: (u8, u8),
        result: MavMissionResult,
        kind: MavMissionType,
    ) -> Vec<Reply> {
        let transfer = self.px4(i).mission.transfer.clone();
        match transfer {
            Transfer::Sending { partner, kind: k, .. } if partner == from && k == kind => {
                self.px4_mut(i).mission.transfer = Transfer::Idle;
                Vec::new()
            }
            Transfer::Getting { partner, next, .. } if partner == from => match result {
                MAV_MISSION_UNSUPPORTED => {
                    let m = &mut self.px4_mut(i).mission;
                    m.int_mode = !m.int_mode;
                    vec![self.request(i, partner, next)]
                }
                MAV_MISSION_OPERATION_CANCELLED => {
                    self.px4_mut(i).mission.transfer = Transfer::Idle;
                    Vec::new()
                }
                _ => Vec::new(),
            },
            Transfer::Idle => Vec::new(),
            _ => self.critical(i, "REJ. WP CMD: partner id mismatch\t"),
        }
    }

    /// MISSION_CLEAR_ALL: the mission is cleared (ACCEPTED), unless a transfer is on.
    pub(crate) fn px4_mission_clear(
        &mut self,
        i: usize,
        from: (u8, u8),
        kind: MavMissionType,
    ) -> Vec<Reply> {
        if !matches!(self.px4(i).mission.transfer, Transfer::Idle) {
            let mut out = self.critical(i, "WPM: IGN CLEAR CMD: Busy\t");
            out.push(self.ack_to(i, from, MAV_MISSION_ERROR, kind, 0));
            return out;
        }
        let mut out = Vec::new();
        if matches!(
            kind,
            MavMissionType::MAV_MISSION_TYPE_MISSION | MavMissionType::MAV_MISSION_TYPE_ALL
        ) {
            out = self.px4_new_mission(i, Vec::new());
        }
        out.push(self.ack_to(i, from, MAV_MISSION_ACCEPTED, kind, 0));
        out
    }

    /// MISSION_SET_CURRENT: the item to fly next (at once, in Mission mode).
    pub(crate) fn px4_mission_set_current(&mut self, i: usize, seq: u16) -> Vec<Reply> {
        if !matches!(self.px4(i).mission.transfer, Transfer::Idle) {
            return self.critical(i, "WPM: IGN WP CURR CMD: Busy\t");
        }
        if usize::from(seq) >= self.px4(i).mission.items.len() {
            return self.critical(i, "WPM: WP CURR CMD: Not in list\t");
        }
        self.px4_set_current(i, seq).into_iter().map(Reply::all).collect()
    }

    /// The current item becomes `seq` (MISSION_SET_CURRENT, MISSION_START's first item).
    pub(crate) fn px4_set_current(&mut self, i: usize, seq: u16) -> Vec<Out> {
        let system = self.copters[i].system;
        let m = &mut self.px4_mut(i).mission;
        m.current = seq;
        m.finished = false;
        let mut out = vec![Out { system, msg: self.px4_mission_current(i).into() }];
        if self.px4(i).nav == Nav::Mission && self.copters[i].armed {
            self.px4_stop(i);
            out.extend(self.px4_item(i, seq));
            out.extend(self.px4_run(i));
        }
        out
    }

    /// A transfer that has heard nothing for 5 s ends.
    pub(crate) fn px4_mission_timeout(&mut self, i: usize, now: f64) -> Vec<Out> {
        let since = match &self.px4(i).mission.transfer {
            Transfer::Idle => return Vec::new(),
            Transfer::Getting { since, .. } | Transfer::Sending { since, .. } => *since,
        };
        if now - since <= TIMEOUT {
            return Vec::new();
        }
        self.px4_mut(i).mission.transfer = Transfer::Idle;
        self.say(i, CRITICAL, "Operation timeout\t")
    }
}
