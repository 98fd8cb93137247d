//! Geofence, ceiling and no-fly zones before flight (docs/LANGUAGE.md, section 22): every
//! place, area, orbit and sweep the mission flies to, where it is known before the run,
//! lies inside the world's geofence, every altitude stays under `max_altitude`, and no
//! flight goes into a no-fly zone or where there is no way around them (`no_fly.rs`).
//!
//! Values are followed from each mission statement into the capabilities it calls (by
//! their parameters and defaults), down to the middle-layer calls that fly. A problem is
//! reported at the mission statement, with the call that flies as a second place.

use std::collections::BTreeMap;

use aviary_api::geometry::{circle_inside, contains, segment_inside};
use aviary_api::show::number;
use aviary_api::{arith, Function, Point};
use aviary_diagnostics::{Code, Diagnostic, FileId, Label, Span};
use aviary_syntax::ast::*;
use aviary_syntax::visit::for_each_stmt;
use aviary_world::World;

use crate::actors::Actors;
use crate::env::{bind_args, capability_bodies};
use crate::Program;

/// How deep capabilities may call each other before the analysis stops following.
const MAX_CALLS: usize = 16;

#[derive(Clone, Debug)]
pub(crate) enum Known {
    Point([f64; 2], Option<f64>),
    Area(Vec<[f64; 2]>),
    /// A line of the world file: its points, each with its height if it has one.
    Path(Vec<([f64; 2], Option<f64>)>),
    Number(f64),
    /// An actor: the world's drones it stands for (indices), for where they start from.
    Drones(Vec<usize>),
}

pub(crate) type Values = BTreeMap<String, Known>;

/// Where a known value stands: a point, or an area's centroid.
fn point_of(k: &Known) -> Option<Point> {
    match k {
        Known::Point([x, y], z) => Some(Point { x: *x, y: *y, z: *z }),
        Known::Area(poly) => {
            let [x, y] = aviary_api::centroid(poly);
            Some(Point::flat(x, y))
        }
        // A line stands nowhere as a point (`FlyTo` refuses one, E107).
        Known::Number(_) | Known::Drones(_) | Known::Path(_) => None,
    }
}

fn known_point(p: Point) -> Known {
    Known::Point([p.x, p.y], p.z)
}

pub(crate) fn check_geofence(
    program: &Program,
    world: &World,
    actors: &Actors,
    diagnostics: &mut Vec<Diagnostic>,
) {
    let (fence, ceiling) = (world.site.geofence.as_deref(), world.site.max_altitude);
    if fence.is_none() && ceiling.is_none() && world.no_fly.is_empty() {
        return;
    }
    let (Some(mission), Some(file)) = (program.mission(), program.mission.map(|r| r.file)) else {
        return;
    };
    let mut walker = Walker {
        program,
        world,
        actors,
        fence,
        ceiling,
        zones: crate::no_fly::Zones::of(world),
        diagnostics,
        budget: follow_budget(&mission.body),
    };
    walker.body(&mission.body, &Values::new(), None, file, 0);
}

pub(crate) struct Walker<'a, 'w> {
    program: &'a Program,
    pub(crate) world: &'a World,
    /// The drones each name of the world stands for.
    pub(crate) actors: &'a Actors<'w>,
    fence: Option<&'a [[f64; 2]]>,
    ceiling: Option<f64>,
    /// The no-fly zones, when the world has any.
    pub(crate) zones: Option<crate::no_fly::Zones>,
    diagnostics: &'a mut Vec<Diagnostic>,
    /// Calls into capabilities the walk may still follow ([`follow_budget`]).
    budget: usize,
}

/// How many calls into capabilities a walk from the mission follows: 64 per mission
/// statement and a million more, generous for any mission's size but finite. Each call is
/// followed where it is made, so capabilities that each call the next ten times make
/// 10^depth calls (up to [`MAX_CALLS`] deep): a mission of a few hundred bytes would
/// otherwise keep `aviary check` busy for years. What is not followed is not checked
/// before flight; the simulator still refuses such a flight (`GeofenceViolation`).
pub(crate) fn follow_budget(mission: &Body) -> usize {
    let mut statements = 0usize;
    for_each_stmt(mission, |s| statements += usize::from(matches!(s, Stmt::Statement(_))));
    statements.saturating_mul(64).saturating_add(1_000_000)
}

impl Walker<'_, '_> {
    fn value(&self, e: &Expr, values: &Values) -> Option<Known> {
        match &e.kind {
            ExprKind::Number { value, unit, .. } => {
                Some(Known::Number(value * unit.map_or(1.0, |u| u.to_si())))
            }
            ExprKind::Coordinates(parts) => {
                let n: Option<Vec<f64>> = parts
                    .iter()
                    .map(|p| match self.value(p, values) {
                        Some(Known::Number(n)) => Some(n),
                        _ => None,
                    })
                    .collect();
                let n = n?;
                Some(Known::Point([n[0], *n.get(1)?], n.get(2).copied()))
            }
            ExprKind::Name(id) => {
                if let Some(v) = values.get(&id.name) {
                    return Some(v.clone());
                }
                if let Some(p) = self.world.place(&id.name) {
                    return Some(Known::Point([p.at[0], p.at[1]], p.has_z.then_some(p.at[2])));
                }
                if let Some(l) = self.world.line(&id.name) {
                    let points = l.points.iter().map(|(p, z)| ([p[0], p[1]], z.then_some(p[2])));
                    return Some(Known::Path(points.collect()));
                }
                self.world.area(&id.name).map(|a| Known::Area(a.polygon.clone()))
            }
            ExprKind::Paren(inner) => self.value(inner, values),
            // Worked out as the compiler folds it (`aviary_api::arith`), when all is known.
            ExprKind::Arith(l, op, r) => {
                let sign = if *op == ArithOp::Add { 1.0 } else { -1.0 };
                match (self.value(l, values)?, self.value(r, values)?) {
                    (Known::Number(a), Known::Number(b)) => Some(Known::Number(a + sign * b)),
                    (p, Known::Point(by, dz)) => {
                        let by = Point { x: by[0], y: by[1], z: dz };
                        Some(known_point(arith::shift(point_of(&p)?, by, sign)))
                    }
                    _ => None,
                }
            }
            ExprKind::Offset(p, d, b) => {
                let p = point_of(&self.value(p, values)?)?;
                match (self.value(d, values)?, self.value(b, values)?) {
                    (Known::Number(d), Known::Number(b)) => {
                        Some(known_point(arith::offset(p, d, b)))
                    }
                    _ => None,
                }
            }
            ExprKind::Midpoint(a, b) => {
                let (a, b) =
                    (point_of(&self.value(a, values)?)?, point_of(&self.value(b, values)?)?);
                Some(known_point(arith::midpoint(a, b)))
            }
            ExprKind::String(_)
            | ExprKind::Bool(_)
            | ExprKind::Geo(_)
            | ExprKind::Path(..)
            | ExprKind::Distance(..)
            | ExprKind::Received(_)
            | ExprKind::Elapsed
            | ExprKind::Not(_)
            | ExprKind::Binary(..)
            | ExprKind::Error => None,
        }
    }

    /// `site`: the mission statement this body runs for, if inside a capability.
    fn body(
        &mut self,
        body: &Body,
        values: &Values,
        site: Option<(FileId, Span)>,
        file: FileId,
        depth: usize,
    ) {
        // The values with those of the LETs reached so far.
        let mut own: Option<Values> = None;
        for stmt in &body.items {
            if let Stmt::Let(l) = stmt {
                let current = own.as_ref().unwrap_or(values);
                let mut next = current.clone();
                match self.value(&l.value, current) {
                    Some(k) => next.insert(l.name.name.clone(), k),
                    None => next.remove(&l.name.name),
                };
                own = Some(next);
                continue;
            }
            let values = own.as_ref().unwrap_or(values);
            match stmt {
                Stmt::Statement(s) => {
                    self.statement(s, values, site.or(Some((file, s.span))), depth)
                }
                Stmt::Api(a) => self.api(a, values, site, file),
                Stmt::For(f) => {
                    for inst in &f.instances {
                        let mut inner = values.clone();
                        inner.remove(&f.alias.name);
                        if let Some(Known::Drones(d)) = self.actor(&inst.actor.name, values) {
                            inner.insert(f.alias.name.clone(), Known::Drones(d));
                        }
                        for (p, v) in f.params.iter().zip(&inst.values) {
                            match self.value(v, values) {
                                Some(k) => inner.insert(p.name.clone(), k),
                                None => inner.remove(&p.name),
                            };
                        }
                        self.body(&f.body, &inner, site, file, depth);
                    }
                }
                Stmt::Any(a) => {
                    let mut inner = values.clone();
                    inner.remove(&a.alias.name);
                    if let Some(Known::Drones(d)) = self.actor(&a.group.name, values) {
                        inner.insert(a.alias.name.clone(), Known::Drones(d));
                    }
                    self.body(&a.body, &inner, site, file, depth);
                }
                Stmt::Handler(h) => {
                    self.body(&h.body, &without(values, &h.bindings), site, file, depth)
                }
                Stmt::ExceptionHandler(h) => {
                    self.body(&h.body, &without(values, &h.bindings), site, file, depth)
                }
                other @ (Stmt::Block(_)
                | Stmt::Leash(_)
                | Stmt::Requirement(_)
                | Stmt::Signal(_)
                | Stmt::Throw(_)
                | Stmt::If(_)
                | Stmt::OperatorSignals(_)
                | Stmt::Let(_)
                | Stmt::Allow(_)
                | Stmt::StopBlock(_)
                | Stmt::Error(_)) => {
                    other.for_each_body(|b| self.body(b, values, site, file, depth))
                }
            }
        }
    }

    fn statement(
        &mut self,
        s: &Statement,
        values: &Values,
        site: Option<(FileId, Span)>,
        depth: usize,
    ) {
        let Some((file, callee)) = self.program.capability_in(&s.capability.name) else {
            return;
        };
        if depth >= MAX_CALLS || self.budget == 0 {
            return;
        }
        self.budget -= 1;
        let binding = bind_args(&callee.params, &s.args);
        let mut inner = Values::new();
        self.bind_actors(callee, s, values, &mut inner);
        for (i, p) in callee.params.iter().enumerate() {
            let known = match binding.bound[i] {
                Some(e) => self.value(e, values),
                None => default_of(callee, &p.name).and_then(|e| self.value(e, &Values::new())),
            };
            if let Some(k) = known {
                inner.insert(p.name.clone(), k);
            }
        }
        for body in capability_bodies(callee) {
            self.body(body, &inner, site, file, depth + 1);
        }
    }

    fn api(&mut self, call: &ApiCall, values: &Values, site: Option<(FileId, Span)>, file: FileId) {
        let known: Vec<Option<Known>> = call.args.iter().map(|e| self.value(e, values)).collect();
        let arg = |i: usize| known.get(i).cloned().flatten();
        // A name the middle layer does not have is the walk's error, not a flight.
        let Some(function) = self.program.api_function(file, call).map(|f| f.function) else {
            return;
        };
        match function {
            Function::FlyToPosition => {
                if let Some(k) = arg(0) {
                    self.point(&k, call, site, file);
                    self.zone_point(&k, None, call, values, site, file);
                }
            }
            Function::TakeOff | Function::AscendTo | Function::DescendTo => {
                if let Some(Known::Number(alt)) = arg(0) {
                    self.altitude(alt, call, site, file);
                }
            }
            Function::Orbit => {
                if let (Some(center), Some(Known::Number(radius))) =
                    (arg(0).and_then(|k| ground(&k)), arg(1))
                {
                    self.zone_circle(center, radius, call, site, file);
                }
                if let (Some(center), Some(Known::Number(radius)), Some(fence)) =
                    (arg(0).and_then(|k| ground(&k)), arg(1), self.fence)
                {
                    if !circle_inside(fence, center, radius) {
                        let what = format!(
                            "the circle of {} m around {} leaves the geofence",
                            number(radius),
                            shown(center)
                        );
                        self.report(Code::LeavesGeofence, what, call, site, file);
                    }
                }
            }
            Function::Sweep => {
                if let Some(Known::Area(area)) = arg(0) {
                    let spacing = match arg(1) {
                        Some(Known::Number(s)) => Some(s),
                        _ => None,
                    };
                    self.zone_sweep(&area, spacing, call, values, site, file);
                }
                if let (Some(Known::Area(area)), Some(fence)) = (arg(0), self.fence) {
                    // A corner outside, or else an edge that crosses the fence.
                    let corner = area.iter().find(|p| !contains(fence, **p));
                    let crossing = || {
                        area.iter()
                            .zip(area.iter().cycle().skip(1))
                            .find(|(p, q)| !segment_inside(fence, **p, **q))
                            .map(|(p, _)| p)
                    };
                    if let Some(p) = corner.or_else(crossing) {
                        let what = format!(
                            "the area swept reaches outside the geofence, at {}",
                            shown(*p)
                        );
                        self.report(Code::LeavesGeofence, what, call, site, file);
                    }
                }
            }
            Function::FollowPath => {
                // A point without a height keeps the one before (unknown before the first).
                let mut z = None;
                // A line stands for its points, in order.
                let known = call.args.iter().flat_map(|e| match self.value(e, values) {
                    Some(Known::Path(points)) => {
                        points.into_iter().map(|(p, h)| Some(Known::Point(p, h))).collect()
                    }
                    k => vec![k],
                });
                for k in known.collect::<Vec<_>>() {
                    match k {
                        Some(k) => {
                            self.point(&k, call, site, file);
                            self.zone_point(&k, z, call, values, site, file);
                            if let Known::Point(_, Some(h)) = k {
                                z = Some(h);
                            }
                        }
                        None => z = None,
                    }
                }
            }
            // Where these fly is not written in the call: the drone's place, or home.
            Function::Arm
            | Function::Disarm
            | Function::Land
            | Function::ReturnToLaunch
            | Function::Hover
            | Function::StartStreaming
            | Function::StopStreaming
            | Function::StartDetection
            | Function::StopDetection
            | Function::LoadPayload
            | Function::ReleasePayload => {}
        }
    }

    fn point(&mut self, k: &Known, call: &ApiCall, site: Option<(FileId, Span)>, file: FileId) {
        if let (Some(p), Some(fence)) = (ground(k), self.fence) {
            if !contains(fence, p) {
                self.report(
                    Code::LeavesGeofence,
                    format!("this flies to {}, outside the geofence", shown(p)),
                    call,
                    site,
                    file,
                );
            }
        }
        if let Known::Point(_, Some(z)) = k {
            self.altitude(*z, call, site, file);
        }
    }

    fn altitude(&mut self, alt: f64, call: &ApiCall, site: Option<(FileId, Span)>, file: FileId) {
        if let Some(ceiling) = self.ceiling {
            if alt > ceiling {
                self.report(
                    Code::AboveCeiling,
                    format!(
                        "this flies at {} m, above the site's max_altitude of {} m",
                        number(alt),
                        number(ceiling)
                    ),
                    call,
                    site,
                    file,
                );
            }
        }
    }

    fn report(
        &mut self,
        code: Code,
        message: String,
        call: &ApiCall,
        site: Option<(FileId, Span)>,
        file: FileId,
    ) {
        // Diagnostic codes, not constructs: the one above the ceiling has help of its own.
        #[allow(clippy::wildcard_enum_match_arm)]
        let help = match code {
            Code::AboveCeiling => "fly lower, or raise `max_altitude` in the world file's [site]",
            _ => {
                "choose a place inside the geofence, or widen `geofence` in the world file's [site]"
            }
        };
        self.report_with(code, message, help.to_owned(), call, site, file);
    }

    /// A finding at the mission statement (`site`), with the call that flies as a second
    /// place.
    pub(crate) fn report_with(
        &mut self,
        code: Code,
        message: String,
        help: String,
        call: &ApiCall,
        site: Option<(FileId, Span)>,
        file: FileId,
    ) {
        let (at_file, at) = site.unwrap_or((file, call.span));
        // Once per statement and finding: a capability that flies the same way on each
        // branch of an IF (the standard library's `FlyTo`, with and without a speed) is
        // one problem of the statement.
        let same = |d: &Diagnostic| {
            d.code == code
                && d.primary.file == at_file
                && d.primary.span == at
                && d.message == message
        };
        if site.is_some() && self.diagnostics.iter().any(same) {
            return;
        }
        let mut d = Diagnostic::new(code, at_file, at, message).with_help(help);
        if site.is_some() {
            d.secondary.push(Label {
                file,
                span: call.span,
                message: format!("{} is called here", call.function.name),
            });
        }
        self.diagnostics.push(d);
    }
}

/// The default a capability's `DEFAULTS` gives parameter `name`, if any (the last, if
/// written twice), looked up only for a parameter the call leaves out.
pub(crate) fn default_of<'c>(callee: &'c Capability, name: &str) -> Option<&'c Expr> {
    callee.sections.iter().rev().find_map(|sec| match sec {
        Section::Defaults { entries, .. } => {
            entries.iter().rev().find(|e| e.name.name == name).map(|e| &e.value)
        }
        Section::Requirements { .. } | Section::Perform { .. } | Section::Exceptions { .. } => None,
    })
}

pub(crate) fn ground(k: &Known) -> Option<[f64; 2]> {
    match k {
        Known::Point(p, _) => Some(*p),
        Known::Area(a) => Some(aviary_api::centroid(a)),
        Known::Path(_) | Known::Number(_) | Known::Drones(_) => None,
    }
}

pub(crate) fn shown(p: [f64; 2]) -> String {
    format!("({}, {})", number(p[0]), number(p[1]))
}

fn without(values: &Values, bound: &[Ident]) -> Values {
    let mut v = values.clone();
    for b in bound {
        v.remove(&b.name);
    }
    v
}
