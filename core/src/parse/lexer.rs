//! Tokens with their line and column, straight from the scene text (no
//! allocation: a token borrows its text).
//!
//! A token is a run of non-whitespace characters; a `/*` or `//` ends it and
//! starts a comment. A token that starts with `"` runs to the next `"` (a
//! quoted file name). Columns count characters, not bytes, from 1.

use super::error::{ErrorKind, ParseError, Pos};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Token<'a> {
    /// The token's text (without the quotes of a quoted string).
    pub text: &'a str,
    /// Where the token starts.
    pub pos: Pos,
    /// Just after its last character (after the closing quote of a quoted
    /// token): where an error for what should have followed it points.
    pub end: Pos,
    pub quoted: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lexer<'a> {
    src: &'a str,
    offset: usize,
    pos: Pos,
}

impl<'a> Lexer<'a> {
    pub fn new(src: &'a str) -> Lexer<'a> {
        Lexer { src, offset: 0, pos: Pos { line: 1, column: 1 } }
    }

    /// Where a text ends: the position just after its last character, as
    /// the lexer counts lines and columns.
    pub fn end_of(text: &'a str) -> Pos {
        let mut lexer = Lexer::new(text);
        while lexer.bump().is_some() {}
        lexer.pos
    }

    fn rest(&self) -> &'a str {
        self.text(self.offset..self.src.len())
    }

    /// The source's text over `range`, whose ends the lexer stepped to
    /// (character boundaries): `get`, whose `None` never comes, rather than
    /// an index whose failure would link a panic's formatting of a
    /// character into a board's flash.
    fn text(&self, range: core::ops::Range<usize>) -> &'a str {
        self.src.get(range).unwrap_or_default()
    }

    /// Steps over the ASCII bytes at the offset that `keep` takes, none of
    /// them a line's end: a column each. What `bump` does for them, without
    /// decoding a character a step (fig5_3's 9 KiB took a Pico 3.3 M cycles
    /// to lex that way, 1.5 M this way).
    fn bump_ascii(&mut self, keep: impl Fn(u8) -> bool) {
        let run = self.rest().bytes().take_while(|&b| b.is_ascii() && b != b'\n' && b != b'\r' && keep(b)).count();
        self.offset += run;
        self.pos.column += run as u32;
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.rest().chars().next()?;
        self.offset += c.len_utf8();
        // A line ends at LF, CRLF or a lone CR (old Mac files).
        if c == '\n' || (c == '\r' && !self.rest().starts_with('\n')) {
            self.pos.line += 1;
            self.pos.column = 1;
        } else {
            self.pos.column += 1;
        }
        Some(c)
    }

    /// Skips whitespace and comments. An unterminated block comment is an
    /// error at the `/*` that opened it; the rest of the text is consumed.
    fn skip_trivia(&mut self) -> Result<(), ParseError<'a>> {
        loop {
            self.bump_ascii(|b| b == b' ' || b == b'\t');
            let rest = self.rest();
            if rest.starts_with("//") {
                while let Some(c) = self.bump() {
                    if c == '\n' || c == '\r' {
                        break;
                    }
                }
            } else if rest.starts_with("/*") {
                let open = self.pos;
                self.bump();
                self.bump();
                loop {
                    if self.rest().starts_with("*/") {
                        self.bump();
                        self.bump();
                        break;
                    }
                    if self.bump().is_none() {
                        return Err(ParseError::new(open, ErrorKind::UnterminatedComment));
                    }
                }
            } else if rest.chars().next().is_some_and(|c| c.is_whitespace() || (c == '\u{feff}' && self.offset == 0)) {
                // A byte-order mark opening the file is whitespace.
                self.bump();
            } else {
                return Ok(());
            }
        }
    }

    /// The next token, `None` at the end of the text.
    pub fn next_token(&mut self) -> Result<Option<Token<'a>>, ParseError<'a>> {
        self.skip_trivia()?;
        let pos = self.pos;
        let start = self.offset;
        match self.rest().chars().next() {
            None => Ok(None),
            Some('"') => {
                self.bump();
                let inner = self.offset;
                loop {
                    match self.bump() {
                        Some('"') => {
                            let text = self.text(inner..self.offset - 1);
                            return Ok(Some(Token { text, pos, end: self.pos, quoted: true }));
                        }
                        Some(_) => {}
                        None => return Err(ParseError::new(pos, ErrorKind::UnterminatedString)),
                    }
                }
            }
            Some(_) => {
                loop {
                    // Neither whitespace nor a comment's `/`.
                    self.bump_ascii(|b| b.is_ascii_graphic() && b != b'/');
                    let rest = self.rest();
                    match rest.chars().next() {
                        Some(c) if !c.is_whitespace() && !rest.starts_with("/*") && !rest.starts_with("//") => {
                            self.bump();
                        }
                        _ => break,
                    }
                }
                Ok(Some(Token { text: self.text(start..self.offset), pos, end: self.pos, quoted: false }))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tokens(src: &str) -> heapless::Vec<(&str, u32, u32), 32> {
        let mut lx = Lexer::new(src);
        let mut out = heapless::Vec::new();
        while let Some(t) = lx.next_token().unwrap() {
            out.push((t.text, t.pos.line, t.pos.column)).unwrap();
        }
        out
    }

    #[test]
    fn tokens_carry_line_and_column() {
        let t = tokens("LIGHT 1.0\n  2 3 4\n");
        assert_eq!(&t[..], &[("LIGHT", 1, 1), ("1.0", 1, 7), ("2", 2, 3), ("3", 2, 5), ("4", 2, 7)]);
    }

    #[test]
    fn a_token_ends_after_its_last_character() {
        let mut lx = Lexer::new("  é1\n");
        let t = lx.next_token().unwrap().unwrap();
        assert_eq!((t.pos, t.end), (Pos { line: 1, column: 3 }, Pos { line: 1, column: 5 }));
    }

    #[test]
    fn comments_of_both_kinds_end_tokens() {
        let t = tokens("A/*x\ny*/B // c\n C//d\nD");
        assert_eq!(&t[..], &[("A", 1, 1), ("B", 2, 4), ("C", 3, 2), ("D", 4, 1)]);
    }

    #[test]
    fn columns_count_characters() {
        let t = tokens("/* é */ X");
        assert_eq!(&t[..], &[("X", 1, 9)]);
    }

    #[test]
    fn quoted_strings() {
        let mut lx = Lexer::new("IMAGEFILE \"my file.png\" x");
        lx.next_token().unwrap();
        let t = lx.next_token().unwrap().unwrap();
        assert_eq!((t.text, t.quoted, t.pos.column, t.end.column), ("my file.png", true, 11, 24));
        assert_eq!(lx.next_token().unwrap().unwrap().text, "x");
    }

    #[test]
    fn unterminated_comment_names_where_it_opened() {
        let mut lx = Lexer::new("A\n  /* never\nclosed");
        lx.next_token().unwrap();
        let e = lx.next_token().unwrap_err();
        assert_eq!(e.pos, Pos { line: 2, column: 3 });
        assert_eq!(e.kind, ErrorKind::UnterminatedComment);
        assert_eq!(lx.next_token().unwrap(), None);
    }

    #[test]
    fn unterminated_string() {
        let mut lx = Lexer::new("\"abc");
        assert_eq!(lx.next_token().unwrap_err().kind, ErrorKind::UnterminatedString);
    }

    /// Random texts of tokens, spaces, tabs, line ends of every kind,
    /// comments, quotes, Unicode whitespace and letters: every token's
    /// start and end are where `end_of` (a character a step) puts them, and
    /// no token holds whitespace or a comment's start.
    #[test]
    fn positions_count_characters_in_any_text() {
        extern crate std;
        use std::string::String;
        const PIECES: [&str; 14] =
            [" ", "\t", "\n", "\r", "\r\n", "/", "*", "a", "1.5", "é", "\u{3000}", "\"", "#", "\u{1}"];
        let mut next = crate::test_rng::seeded(0x1e8e_12c0_1a11);
        for _ in 0..20_000 {
            let src: String = (0..next() % 40).map(|_| PIECES[(next() % PIECES.len() as u64) as usize]).collect();
            let mut lexer = Lexer::new(&src);
            while let Ok(Some(token)) = lexer.next_token() {
                let start = token.text.as_ptr() as usize - src.as_ptr() as usize;
                let (start, end) = if token.quoted {
                    (start - 1, start + token.text.len() + 1)
                } else {
                    (start, start + token.text.len())
                };
                assert_eq!(
                    (token.pos, token.end),
                    (Lexer::end_of(&src[..start]), Lexer::end_of(&src[..end])),
                    "{src:?}"
                );
                if !token.quoted {
                    let text = token.text;
                    assert!(
                        !text.contains(char::is_whitespace) && !text.contains("//") && !text.contains("/*"),
                        "{src:?}"
                    );
                }
            }
        }
    }
}
