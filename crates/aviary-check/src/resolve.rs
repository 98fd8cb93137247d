//! The middle-layer function each API call names (`drone.Hover(10s)`), resolved from its
//! name once, when the program is loaded, for every pass after it: the walk (the call's
//! arguments, and E109 for a name the middle layer lacks), kind inference, the signals'
//! values, the geofence and endurance walks, and the lowering. One place turns a call's
//! text into a function, so no two passes can read one call differently, and none scans
//! the descriptor's names again.
//!
//! A call is known by its file and where its function's name starts: a key every pass
//! has at hand (each knows the file it walks) and that names the same call in any copy of
//! the tree, as a node's address would not. Two calls cannot start their names at one
//! byte of one file.

use aviary_api::{Descriptor, Signature};
use aviary_diagnostics::FileId;
use aviary_syntax::ast::{ApiCall, Expr, SourceFile, Stmt};
use aviary_syntax::visit::{walk_source_file, walk_stmt, Visitor};

/// Each API call's function, by the call's file and the start of its function's name.
/// A call whose name the middle layer does not have is not in the table: the walk reports
/// it (E109), and every other pass passes it over (an unknown name is no flight).
#[derive(Default)]
pub(crate) struct ApiFunctions(foldhash::HashMap<(FileId, u32), &'static Signature>);

impl ApiFunctions {
    /// Every call of every file, in every body (a mission's, a capability's sections and
    /// handlers, overridden or not), so that a pass finds each call it meets.
    pub(crate) fn of(files: &[(FileId, SourceFile)]) -> ApiFunctions {
        struct Calls<'t> {
            file: FileId,
            api: &'static Descriptor,
            table: &'t mut foldhash::HashMap<(FileId, u32), &'static Signature>,
        }
        impl<'a> Visitor<'a> for Calls<'_> {
            fn visit_stmt(&mut self, stmt: &'a Stmt) {
                if let Stmt::Api(call) = stmt {
                    if let Some(f) = self.api.function(&call.function.name) {
                        self.table.insert((self.file, call.function.span.start), f);
                    }
                }
                walk_stmt(self, stmt);
            }
            // Expressions hold no statements.
            fn visit_expr(&mut self, _: &'a Expr) {}
        }
        let (api, mut table) = (Descriptor::standard(), foldhash::HashMap::default());
        for (file, tree) in files {
            walk_source_file(&mut Calls { file: *file, api, table: &mut table }, tree);
        }
        ApiFunctions(table)
    }

    pub(crate) fn get(&self, file: FileId, call: &ApiCall) -> Option<&'static Signature> {
        self.0.get(&(file, call.function.span.start)).copied()
    }
}

#[cfg(test)]
mod tests {
    use aviary_api::Function;
    use aviary_diagnostics::SourceMap;
    use aviary_syntax::ast::Stmt;
    use aviary_syntax::visit::for_each_stmt;

    use crate::env::item_bodies;
    use crate::NoFiles;

    /// Every call of every body is resolved, to the function its name says; a name the
    /// middle layer lacks, to none (and the walk reports it, at the name, as before).
    #[test]
    fn every_call_is_resolved_to_the_function_it_names() {
        let text = "MISSION M:\n    scout Look WITH 5s\n\n\
            CAPABILITY Look BY d WITH t:\n    PERFORM:\n        d.TakeOff(10m)\n        PARALLEL:\n            d.Hover(t)\n            ON Go:\n                d.Land()\n    PERFORM ABORT:\n        d.ReturnToLaunch()\n    EXCEPTIONS:\n        ON EXCEPTION BatteryCritical:\n            d.Hoverr(t)\n";
        let mut sources = SourceMap::new();
        let root = sources.add("m.mission", text);
        let (program, diagnostics) = crate::check(&mut sources, root, None, &NoFiles);
        let mut seen = Vec::new();
        for (file, tree) in &program.files {
            for item in &tree.items {
                for body in item_bodies(item) {
                    for_each_stmt(body, |stmt| {
                        if let Stmt::Api(call) = stmt {
                            let resolved = program.api_function(*file, call).map(|f| f.function);
                            assert_eq!(resolved, Function::from_name(&call.function.name));
                            if *file == root {
                                seen.push(resolved);
                            }
                        }
                    });
                }
            }
        }
        use Function::*;
        assert_eq!(
            seen,
            [Some(TakeOff), Some(Hover), Some(Land), Some(ReturnToLaunch), None],
            "{diagnostics:?}"
        );
        let unknown: Vec<_> = diagnostics
            .iter()
            .filter(|d| d.code == aviary_diagnostics::Code::UnknownApiFunction)
            .map(|d| &text[d.primary.span.start as usize..d.primary.span.end as usize])
            .collect();
        assert_eq!(unknown, ["Hoverr"]);
    }
}
