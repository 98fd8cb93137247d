use aviary_diagnostics::Span;

macro_rules! keywords {
    ($($name:ident = $text:literal,)*) => {
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Keyword { $($name,)* }
        impl Keyword {
            pub const ALL: &'static [Keyword] = &[$(Keyword::$name,)*];
            pub fn as_str(self) -> &'static str {
                match self { $(Keyword::$name => $text,)* }
            }
            pub fn from_exact(text: &str) -> Option<Keyword> {
                match text { $($text => Some(Keyword::$name),)* _ => None }
            }
        }
    };
}

keywords! {
    Mission = "MISSION", Sequential = "SEQUENTIAL", Parallel = "PARALLEL", On = "ON",
    Every = "EVERY", By = "BY", With = "WITH", For = "FOR", And = "AND", As = "AS",
    Signal = "SIGNAL", Throw = "THROW", Exception = "EXCEPTION", StartIf = "STARTIF",
    WaitFor = "WAITFOR", DoWhile = "DOWHILE", If = "IF", Else = "ELSE",
    Capability = "CAPABILITY", Requirements = "REQUIREMENTS", Defaults = "DEFAULTS",
    Perform = "PERFORM", Exceptions = "EXCEPTIONS", Abort = "ABORT", Pause = "PAUSE",
    Resume = "RESUME", Use = "USE", Not = "NOT", Or = "OR", True = "TRUE", False = "FALSE",
}

impl Keyword {
    /// The keyword this word would be if it were upper case.
    pub fn from_any_case(text: &str) -> Option<Keyword> {
        // Upper-cased on the stack: this runs for many words of a mission, and no keyword
        // is longer than the buffer.
        let mut upper = [0u8; 16];
        let word = upper.get_mut(..text.len())?;
        word.copy_from_slice(text.as_bytes());
        word.make_ascii_uppercase();
        Keyword::from_exact(std::str::from_utf8(word).ok()?)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TokenKind {
    Ident,
    Keyword(Keyword),
    /// `Name-Tag`, glued: one token.
    TaggedName,
    /// Digits, with a unit glued on when there is one (`20m`, `5m/s`, `25%`).
    Number,
    String,
    Colon,
    Comma,
    LParen,
    RParen,
    Dot,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    Minus,
    /// `+`: only between values (`where + (20m, 0m)`).
    Plus,
    Slash,
    /// A character with no meaning; the lexer has already reported it.
    Unknown,
    Newline,
    Indent,
    Dedent,
    Eof,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Token {
    pub kind: TokenKind,
    pub span: Span,
}

impl TokenKind {
    pub fn describe(self) -> String {
        match self {
            TokenKind::Ident => "a name".into(),
            TokenKind::Keyword(k) => format!("`{}`", k.as_str()),
            TokenKind::TaggedName => "a tagged name".into(),
            TokenKind::Number => "a number".into(),
            TokenKind::String => "a string".into(),
            TokenKind::Colon => "`:`".into(),
            TokenKind::Comma => "`,`".into(),
            TokenKind::LParen => "`(`".into(),
            TokenKind::RParen => "`)`".into(),
            TokenKind::Dot => "`.`".into(),
            TokenKind::Eq => "`=`".into(),
            TokenKind::Ne => "`!=`".into(),
            TokenKind::Lt => "`<`".into(),
            TokenKind::Le => "`<=`".into(),
            TokenKind::Gt => "`>`".into(),
            TokenKind::Ge => "`>=`".into(),
            TokenKind::Minus => "`-`".into(),
            TokenKind::Plus => "`+`".into(),
            TokenKind::Slash => "`/`".into(),
            TokenKind::Unknown => "an unknown character".into(),
            TokenKind::Newline => "the end of the line".into(),
            TokenKind::Indent => "an indented line".into(),
            TokenKind::Dedent => "the end of the block".into(),
            TokenKind::Eof => "the end of the file".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Keyword;

    #[test]
    fn every_keyword_is_found_in_any_case_and_longer_words_are_not_keywords() {
        for &k in Keyword::ALL {
            let lower = k.as_str().to_ascii_lowercase();
            assert_eq!(Keyword::from_any_case(&lower), Some(k));
            assert_eq!(Keyword::from_any_case(k.as_str()), Some(k));
        }
        assert_eq!(Keyword::from_any_case("sequentially"), None);
        assert_eq!(Keyword::from_any_case("a_very_long_name_indeed_of_a_drone"), None);
        assert_eq!(Keyword::from_any_case("ünicode"), None);
    }
}
