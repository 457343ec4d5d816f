//! A scene text read statement after statement: each statement, or its
//! error, in the order of the text, resynchronising after an error.
//!
//! Invariants: every error is reported once, at its line and column; a
//! line that begins with a word is always read again as a statement.

use super::error::{ErrorKind, ParseError, Pos};
use super::keyword::Keyword;
use super::lexer;
use super::number::Decimal;
use super::statement::{self, Cursor, Room, Statement};

/// Reads every statement of `text`, handing each (or its error) to `each`
/// with its keyword (`None` for a word that is none, or a lexical error);
/// after an error, resynchronises at the next statement (see [`recover`]).
pub(crate) fn for_each_statement<'a, R: Room>(
    text: &'a str,
    mut each: impl FnMut(Pos, Option<Keyword>, Result<Statement<'a>, ParseError<'a>>),
) {
    let mut cur = Cursor::new(text);
    loop {
        let token = match cur.next() {
            Ok(Some(t)) => t,
            Ok(None) => return,
            Err(e) => {
                each(e.pos, None, Err(e));
                continue;
            }
        };
        let keyword = Keyword::from_text(token.text).filter(|_| !token.quoted);
        let result = match keyword {
            Some(kw) => statement::statement::<R>(&mut cur, kw, token.pos),
            None => Err(ParseError::new(token.pos, ErrorKind::UnknownKeyword(token.text))),
        };
        let error_at = result.as_ref().err().map(|e| e.pos);
        each(token.pos, keyword, result);
        if let Some(pos) = error_at {
            recover(&mut cur, pos, &mut |e| each(e.pos, None, Err(e)));
        }
    }
}

/// After an error at `at`, skips to where the next statement begins: a
/// keyword, or a word (not a number) that is the first token of its line.
/// The offending token goes first unless it is a keyword; numbers after it
/// are the bad statement's (a B-spline's points span lines), whatever line
/// they are on. So every line that begins with a word is read again as a
/// statement, and its error, if any, is reported too: five lines of `x`
/// give five errors. A lexer error met while skipping goes to `lexical`.
fn recover<'a>(cur: &mut Cursor<'a>, at: Pos, lexical: &mut dyn FnMut(ParseError<'a>)) {
    let begins_statement = |t: &lexer::Token<'_>| !t.quoted && Keyword::from_text(t.text).is_some();
    let number = |t: &lexer::Token<'_>| !t.quoted && Decimal::parse(t.text).is_some();
    loop {
        match cur.peek() {
            Ok(None) => return,
            Ok(Some(t)) if begins_statement(&t) => return,
            // The offending token, left for recovery by the statement.
            Ok(Some(t)) if t.pos == at => {}
            Ok(Some(t)) if !number(&t) && cur.on_a_later_line(t) => return,
            Ok(Some(_)) => {}
            Err(e) => {
                lexical(e);
                continue;
            }
        }
        let _ = cur.next();
    }
}
