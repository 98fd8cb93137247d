//! The station's own documents on the wire (`/api/station/...`), typed: what the page
//! reads. The operator API's are `aviary_api::operator`'s; the check's are `checking.rs`'s.

use serde::{Serialize, Serializer};
use serde_json::Value;

/// `GET /api/station`: what the page needs to know first.
#[derive(Debug, Serialize)]
pub struct About {
    /// `station` (a folder), `run` (`aviary run --serve`) or `replay`.
    pub mode: &'static str,
    /// The token is needed to read (the station is bound beyond loopback).
    pub reading_needs_token: bool,
    /// Where the folder is on the station's machine: the editor names its files to the
    /// language server by their absolute path (`file://` URIs).
    pub folder: Option<String>,
    /// Whether `/api/lsp` has a language server to give.
    pub lsp: bool,
    /// The flight in progress, or the last one.
    pub run: Option<RunShown>,
    /// The world of the flight or trace shown, as the map draws it.
    pub map: Value,
}

/// What the page is shown of a flight.
#[derive(Clone, Debug, Serialize)]
pub struct RunShown {
    pub mission: String,
    pub tree: Value,
    /// Where its trace is written, for a flight from the page.
    pub trace: Option<String>,
    #[serde(skip_serializing_if = "VehiclePlan::is_none")]
    pub vehicle_plan: VehiclePlan,
}

/// What the page is told of the plan made with the MAVLink vehicles' own figures: absent
/// without a MAVLink drone, `"due"` while the vehicles are asked, then its warnings.
#[derive(Clone, Debug, Default)]
pub enum VehiclePlan {
    #[default]
    None,
    Due,
    Made(Vec<VehicleWarning>),
}

impl VehiclePlan {
    fn is_none(&self) -> bool {
        matches!(self, VehiclePlan::None)
    }
}

impl Serialize for VehiclePlan {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            VehiclePlan::None => s.serialize_none(),
            VehiclePlan::Due => s.serialize_str("due"),
            VehiclePlan::Made(warnings) => warnings.serialize(s),
        }
    }
}

/// One warning of the plan made again with a vehicle's figures.
#[derive(Clone, Debug, Serialize)]
pub struct VehicleWarning {
    /// The drone that runs out, for a W204 of the plan's own.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drone: Option<String>,
    pub code: &'static str,
    pub text: String,
    /// Red (the drone runs out before the end), not orange.
    pub severe: bool,
}

/// `GET /api/station/file`: a file of the folder.
#[derive(Debug, Serialize)]
pub struct Opened {
    pub path: String,
    pub text: String,
}

/// `POST /api/station/fly` refused: why, and the check that says what to fix.
#[derive(Debug, Serialize)]
pub struct FlyRefused {
    pub error: &'static str,
    pub check: Value,
}

/// `POST /api/station/campaign`: the report as `aviary test` prints it, and its page.
#[derive(Debug, Serialize)]
pub struct CampaignReport {
    pub text: String,
    pub html: String,
}
