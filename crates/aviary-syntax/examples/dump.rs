fn main() {
    let path = std::env::args().nth(1).expect("path");
    let bytes = std::fs::read(&path).expect("read");
    let mut sources = aviary_diagnostics::SourceMap::new();
    let (text, parse) = aviary_syntax::parse_bytes(aviary_diagnostics::FileId(0), &bytes);
    sources.add(path, text.clone());
    if std::env::args().nth(2).as_deref() == Some("tree") {
        println!("{:#?}", parse.tree);
    }
    if std::env::args().nth(2).as_deref() == Some("fmt") {
        print!("{}", aviary_syntax::format(&parse.tree, &text, &parse.line_starts));
    }
    for d in &parse.diagnostics {
        print!("{}", aviary_diagnostics::render_text(&sources, d, false));
    }
}
