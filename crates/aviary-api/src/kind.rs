/// What kind of value a parameter takes or an expression gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    Length,
    Duration,
    Speed,
    Angle,
    /// A fraction; written with `%`.
    Ratio,
    /// A plain number with no unit (laps, rounds).
    Number,
    Text,
    Bool,
    /// A point: coordinates, `GEO(...)`, a place, or an area (its centroid).
    Position,
    Area,
    /// A name that only equals itself (`Body`, `Landed`).
    Symbol,
    Actor,
    /// A line of the world file's `[lines]`: points in order, flown by `FollowPath`.
    Line,
    /// What `FollowPath` flies through: positions, a line of the world file, or what a
    /// `Sweep` or `FollowPath` left.
    Path,
    /// What a `Sweep` or `FollowPath` left (`drone.remaining`): taken by `Sweep` in place
    /// of an area and by `FollowPath` in place of its points, and nowhere else.
    Remainder,
}

impl Kind {
    /// How a person would call it in a message.
    pub fn describe(self) -> &'static str {
        match self {
            Kind::Length => "a length (m, km)",
            Kind::Duration => "a duration (s, min, h)",
            Kind::Speed => "a speed (m/s, km/h)",
            Kind::Angle => "an angle (deg)",
            Kind::Ratio => "a ratio (%)",
            Kind::Number => "a plain number",
            Kind::Text => "a string",
            Kind::Bool => "TRUE or FALSE",
            Kind::Position => "a position (a place, an area, or coordinates)",
            Kind::Area => "an area",
            Kind::Symbol => "a symbol",
            Kind::Actor => "a drone or group",
            Kind::Line => "a line (of the world file's [lines])",
            Kind::Path => "a path (positions, a line of the world file, or what a FollowPath left)",
            Kind::Remainder => "what a Sweep or FollowPath left (`drone.remaining`)",
        }
    }

    /// Whether a value of kind `value` may stand where `self` is expected.
    pub fn accepts(self, value: Kind) -> bool {
        self == value
            || matches!(
                (self, value),
                (Kind::Position, Kind::Area)
                    | (Kind::Area, Kind::Remainder)
                    | (Kind::Path, Kind::Position | Kind::Area | Kind::Line | Kind::Remainder)
                    | (Kind::Symbol, Kind::Text)
                    | (Kind::Text, Kind::Symbol)
            )
    }

    /// An example literal of this kind, for help lines.
    pub fn example(self) -> &'static str {
        match self {
            Kind::Length => "20m",
            Kind::Duration => "30s",
            Kind::Speed => "5m/s",
            Kind::Angle => "90deg",
            Kind::Ratio => "25%",
            Kind::Number => "2",
            Kind::Text => "\"text\"",
            Kind::Bool => "TRUE",
            Kind::Position => "(100, 50)",
            Kind::Area => "an area from the world file",
            Kind::Symbol => "Body",
            Kind::Actor => "a drone's name",
            Kind::Line => "a line from the world file",
            Kind::Path => "(100, 50), (200, 50)",
            Kind::Remainder => "drone.remaining",
        }
    }
}
