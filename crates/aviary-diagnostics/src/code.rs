//! The registry of diagnostic codes. A code never changes meaning once published;
//! `docs/DIAGNOSTICS.md` explains each one, and a test keeps the two in step.

use crate::Severity;

macro_rules! codes {
    ($($name:ident = $id:literal, $sev:ident, $summary:literal;)*) => {
        /// A stable diagnostic code.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Code { $($name,)* }

        impl Code {
            pub const ALL: &'static [Code] = &[$(Code::$name,)*];
            pub fn as_str(self) -> &'static str {
                match self { $(Code::$name => $id,)* }
            }
            pub fn severity(self) -> Severity {
                match self { $(Code::$name => Severity::$sev,)* }
            }
            /// One line on what the code means, for docs and `--explain`.
            pub fn summary(self) -> &'static str {
                match self { $(Code::$name => $summary,)* }
            }
            /// The code written `id` (`"E107"`), if there is one.
            #[allow(clippy::should_implement_trait)]
            pub fn from_str(id: &str) -> Option<Code> {
                match id { $($id => Some(Code::$name),)* _ => None }
            }
        }
    };
}

codes! {
    // Reading the file.
    InvalidUtf8 = "E001", Error, "the file is not valid UTF-8 text";
    BinaryFile = "E002", Error, "the file holds binary data (NUL bytes), not mission text";
    EmptyFile = "E003", Error, "the file is empty";
    TabIndent = "E004", Error, "a tab in indentation; indent with spaces";
    InconsistentDedent = "E005", Error, "a dedent that matches no enclosing indentation level";
    UnexpectedIndent = "E006", Error, "a line indented deeper than its block allows";
    ExpectedBlock = "E007", Error, "a header ending in `:` with no indented body";
    Syntax = "E008", Error, "the text does not fit the grammar here";
    UnterminatedString = "E009", Error, "a string with no closing quote";
    UnterminatedComment = "E010", Error, "a `/*` comment with no closing `*/`";
    UnknownCharacter = "E011", Error, "a character that has no meaning in the language";
    UnknownUnit = "E012", Error, "a number with a unit the language does not know";
    NestingTooDeep = "E013", Error, "blocks or expressions nested deeper than the limit";
    SpacedTag = "E014", Error, "an activity tag written with spaces around `-`";
    KeywordCase = "E015", Error, "a keyword not written in upper case";
    PaperForm = "E016", Error, "a form from the paper that this language writes differently";
    MissingColon = "E017", Error, "a header that does not end in `:`";
    TooManyErrors = "E018", Error, "so many syntax errors that reading stopped";
    MisplacedItem = "E019", Error, "an item where it is not allowed (ELSE without IF, a section outside a capability, ...)";
    MissingPerform = "E020", Error, "a capability without its nameless PERFORM section";
    InvalidNumber = "E021", Error, "a number that cannot be read";
    // Names, arguments and kinds.
    UnknownCapability = "E101", Error, "a statement names a capability that is not defined";
    UnknownActor = "E102", Error, "an actor that is no drone, group, alias or parameter";
    UnknownPlace = "E103", Error, "a name where a place or area is expected that names none";
    UnknownArgument = "E104", Error, "a named argument the capability does not have";
    MissingArgument = "E105", Error, "a parameter with no argument and no default";
    TooManyArguments = "E106", Error, "more positional arguments than parameters";
    WrongKind = "E107", Error, "a value of the wrong kind (a duration where a length is expected, ...)";
    ApiCallOutsideCapability = "E108", Error, "a middle-layer API call outside a capability";
    UnknownApiFunction = "E109", Error, "an API call to a function the middle layer does not have";
    UnknownTag = "E110", Error, "a leash on an activity tag that no statement defines";
    DuplicateCapability = "E111", Error, "two capabilities of one name";
    DuplicateMission = "E112", Error, "more than one MISSION";
    UseNotFound = "E113", Error, "a USE of a file that cannot be read";
    ArgumentsWithoutWith = "E114", Error, "a statement whose arguments do not follow WITH";
    DuplicateArgument = "E115", Error, "one parameter given two arguments";
    UnknownLeashSection = "E116", Error, "a leash call to a section the capability does not define";
    ActorCount = "E117", Error, "a statement with a number of actors the capability cannot take";
    UnknownTelemetry = "E118", Error, "`a.b` where b is no telemetry field or attribute of a";
    WorldFile = "E119", Error, "the world file is not valid";
    UnknownParameter = "E120", Error, "a DEFAULTS entry for a name that is not a parameter";
    DuplicateParameter = "E121", Error, "a capability that declares one parameter twice";
    SignalNeverRaised = "E122", Error, "a WAITFOR RECEIVED(X) where nothing raises X";
    ApiCallOnNonActor = "E123", Error, "an API call on something that is not the capability's actor";
    LeavesGeofence = "E124", Error, "a flight to a place, area, orbit or sweep that leaves the geofence";
    AboveCeiling = "E125", Error, "an altitude above the site's max_altitude";
    UnboundedRecursion = "E126", Error, "a capability that calls itself, directly or through others, with nothing to stop it";
    UseRefused = "E127", Error, "a USE of a file that is not a .mission file under the mission's folder (or a --use-root), or not a regular file of at most 16 MiB";
    IntoNoFlyZone = "E128", Error, "a flight into a no-fly zone, or one with no way around the zones inside the geofence";
    OneAtATimeNotEvery = "E129", Error, "`ONE AT A TIME` on a handler that is not an `ON EVERY`";
    OperatorSignalBuiltin = "E130", Error, "an OPERATOR SIGNAL that names a built-in signal, which only a drone raises";
    GroupRemainder = "E131", Error, "`group.remaining`: a remainder is one drone's, not a group's";
    LetTaken = "E132", Error, "a LET of a name that is already bound here (another LET, a parameter, an alias, a drone, a place, ...)";
    LetNotHere = "E133", Error, "a name used where its LET does not reach: before it, outside its body, or in a handler that may fire before it";
    AllowInvalid = "E134", Error, "an ALLOW of a code that is no warning's, or with no item after it";
    UnknownBlock = "E135", Error, "a block's ABORT that names no named SEQUENTIAL or PARALLEL block";
    AnyNotGroup = "E140", Error, "an ANY that chooses from something that is not a group of the world";
    AnyCount = "E141", Error, "an ANY that asks for a number of drones its group cannot give (not a whole number from 1 to the group's size)";
    // Warnings.
    HandlerNeverFires = "W201", Warning, "a handler for a signal that nothing raises";
    UnknownException = "W202", Warning, "an ON EXCEPTION for a name neither built in nor thrown";
    CommandsMayCollide = "W203", Warning, "one drone commanded from two places that may run at once";
    LowReserve = "W204", Warning, "a drone's estimated battery reserve falls under 20%";
    PastEndurance = "W205", Warning, "a duration (such as Hover's) longer than the drone's endurance";
    HandlerRethrows = "W206", Warning, "an ON EXCEPTION that throws the exception it handles before doing anything else";
    SignalNeverHeard = "W207", Warning, "a handler of a drone's built-in signal that can never hear it: the drone never works inside its block";
    OperatorSignalTwice = "W208", Warning, "a signal declared twice with OPERATOR SIGNAL";
    SignalCycle = "W209", Warning, "ON EVERY handlers that raise one another's signals at once, in a cycle that takes no time";
    OutOfRadioReach = "W210", Warning, "a drone's planned path leaves the reach of the station's radio and of every relay";
    AllowUnused = "W211", Warning, "an ALLOW that matches no warning on the item after it";
    // Notes.
    SignalNeverHandled = "N301", Note, "a signal raised but never handled";
    NoWorld = "N302", Note, "no world file, so actors, places and areas were not checked";
    CommandsQueue = "N303", Note, "a handler that may wait for its drone, held by the flow that raised its signal or by another firing of itself";
}

impl Code {
    /// The codes of the pre-flight analyses that run on the compiled mission
    /// (`aviary-verify`), not in the checker.
    pub const PREFLIGHT: &'static [Code] =
        &[Code::CommandsMayCollide, Code::LowReserve, Code::OutOfRadioReach, Code::CommandsQueue];
}

impl std::fmt::Display for Code {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}
