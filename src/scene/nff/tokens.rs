//! NFF's tokens: whitespace-separated words, `#` to the end of a line
//! skipped, each with its line, column and byte offset, read one at a time.

use std::ops::{Range, RangeInclusive};
use std::path::Path;

use crate::limits::{check_color, check_range};
use crate::math::DVec3;
use crate::scene::model::{Location, SceneError};

#[derive(Clone, Copy)]
pub(super) struct Token<'a> {
    pub(super) text: &'a str,
    pub(super) line: usize,
    pub(super) column: usize,
    /// Byte offset in the file's text.
    pub(super) offset: usize,
}

impl Token<'_> {
    const NONE: Token<'static> = Token {
        text: "",
        line: 1,
        column: 1,
        offset: 0,
    };
}

/// The whitespace-separated tokens of the text, `#` to the end of a line
/// skipped, each found when asked for: a file of a million triangles holds
/// 13 million tokens, which kept in a list took 530 MB.
struct Scanner<'a> {
    text: &'a str,
    /// Byte offset of the next character to look at.
    pos: usize,
    /// Line of `pos`, from 1.
    line: usize,
    /// Characters of the current line before byte offset `counted_to`
    /// (counted once, so long lines cost no more than short ones).
    column: usize,
    counted_to: usize,
}

impl<'a> Iterator for Scanner<'a> {
    type Item = Token<'a>;

    fn next(&mut self) -> Option<Token<'a>> {
        let text = self.text;
        loop {
            let c = text[self.pos..].chars().next()?;
            if c == '\n' {
                self.pos += 1;
                self.line += 1;
                self.column = 0;
                self.counted_to = self.pos;
            } else if c == '#' {
                self.pos = text[self.pos..]
                    .find('\n')
                    .map_or(text.len(), |j| self.pos + j);
            } else if c.is_whitespace() {
                self.pos += c.len_utf8();
            } else {
                break;
            }
        }
        let start = self.pos;
        let tail = &text[start..];
        let len = tail
            .find(|c: char| c.is_whitespace() || c == '#')
            .unwrap_or(tail.len());
        self.pos = start + len;
        self.column += text[self.counted_to..start].chars().count();
        self.counted_to = start;
        Some(Token {
            text: &tail[..len],
            line: self.line,
            column: self.column + 1,
            offset: start,
        })
    }
}

/// How many of the last tokens read are remembered (a material's `f`
/// entity has eight numbers whose places the layout keeps).
const RECENT: usize = 8;

pub(super) struct Tokens<'a> {
    path: &'a Path,
    scanner: Scanner<'a>,
    /// The next token, once looked at.
    peeked: Option<Option<Token<'a>>>,
    /// The last `RECENT` tokens read, the newest at `read % RECENT`.
    recent: [Token<'a>; RECENT],
    read: usize,
    /// Place of the entity being read, for "ended too early" errors.
    pub(super) entity: (usize, usize, &'a str),
}

impl<'a> Tokens<'a> {
    pub(super) fn new(text: &'a str, path: &'a Path) -> Self {
        Self {
            path,
            scanner: Scanner {
                text,
                pos: 0,
                line: 1,
                column: 0,
                counted_to: 0,
            },
            peeked: None,
            recent: [Token::NONE; RECENT],
            read: 0,
            entity: (1, 1, ""),
        }
    }

    /// The next token, without reading it.
    pub(super) fn peek(&mut self) -> Option<Token<'a>> {
        *self.peeked.get_or_insert_with(|| self.scanner.next())
    }

    /// Reads the next token, if any.
    pub(super) fn advance(&mut self) -> Option<Token<'a>> {
        let t = self.peeked.take().unwrap_or_else(|| self.scanner.next())?;
        self.read += 1;
        self.recent[self.read % RECENT] = t;
        Some(t)
    }

    pub(super) fn error_at(
        &self,
        line: usize,
        column: usize,
        key: &str,
        message: impl Into<String>,
    ) -> SceneError {
        SceneError::Invalid {
            location: Location {
                path: self.path.to_owned(),
                line,
                column,
                key: key.to_owned(),
            },
            message: message.into(),
        }
    }

    /// The next token, or an error at the entity being read naming what
    /// it still needed and the line where the file ended.
    pub(super) fn next_token(&mut self, what: &str) -> Result<Token<'a>, SceneError> {
        self.advance().ok_or_else(|| {
            let (line, column, key) = self.entity;
            let last = self.scanner.text.lines().count().max(1);
            self.error_at(
                line,
                column,
                key,
                format!("file ends at line {last} while reading {what}"),
            )
        })
    }

    pub(super) fn number(&mut self, what: &str) -> Result<f64, SceneError> {
        let key = self.entity.2;
        let t = self.next_token(what)?;
        let (text, line, column) = (t.text, t.line, t.column);
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            Ok(x) => {
                Err(self.error_at(line, column, key, format!("{what} must be finite, got {x}")))
            }
            Err(_) => Err(self.error_at(
                line,
                column,
                key,
                format!("expected a number for {what}, got `{text}`"),
            )),
        }
    }

    pub(super) fn vec3(&mut self, what: &str) -> Result<DVec3, SceneError> {
        Ok(DVec3::new(
            self.number(what)?,
            self.number(what)?,
            self.number(what)?,
        ))
    }

    /// A number in `range`; errors point at the number.
    pub(super) fn number_in(
        &mut self,
        what: &str,
        range: &RangeInclusive<f64>,
    ) -> Result<f64, SceneError> {
        let (line, column) = self.peek_place();
        let x = self.number(what)?;
        check_range(x, range)
            .map_err(|e| self.error_at(line, column, self.entity.2, format!("{what} {e}")))
    }

    /// Three numbers in `range`; errors point at the first.
    pub(super) fn color_in(
        &mut self,
        what: &str,
        range: &RangeInclusive<f64>,
    ) -> Result<DVec3, SceneError> {
        let (line, column) = self.peek_place();
        let c = self.vec3(what)?;
        check_color(c, range)
            .map_err(|e| self.error_at(line, column, self.entity.2, format!("{what}: {e}")))
    }

    /// Byte ranges of the last `N` tokens read (`N` at most `RECENT`).
    pub(super) fn last<const N: usize>(&self) -> [Range<usize>; N] {
        const { assert!(N <= RECENT) };
        std::array::from_fn(|k| {
            let t = &self.recent[(self.read + RECENT + 1 - N + k) % RECENT];
            t.offset..t.offset + t.text.len()
        })
    }

    /// Line and column of the token just read.
    pub(super) fn last_place(&self) -> (usize, usize) {
        let t = &self.recent[self.read % RECENT];
        (t.line, t.column)
    }

    /// Line and column of the next token (or of the entity, at the end).
    pub(super) fn peek_place(&mut self) -> (usize, usize) {
        let entity = (self.entity.0, self.entity.1);
        self.peek().map_or(entity, |t| (t.line, t.column))
    }

    pub(super) fn count(&mut self, what: &str, max: usize) -> Result<usize, SceneError> {
        let key = self.entity.2;
        let t = self.next_token(what)?;
        let (text, line, column) = (t.text, t.line, t.column);
        match text.parse::<usize>() {
            Ok(n) if n <= max => Ok(n),
            _ => Err(self.error_at(
                line,
                column,
                key,
                format!("{what} must be a whole number up to {max}, got `{text}`"),
            )),
        }
    }

    /// Reads the label of a `v` entity's line, e.g. `from`.
    pub(super) fn label(&mut self, expected: &str) -> Result<(), SceneError> {
        let key = self.entity.2;
        let t = self.next_token(&format!("its `{expected}` line"))?;
        if t.text == expected {
            Ok(())
        } else {
            let (text, line, column) = (t.text, t.line, t.column);
            Err(self.error_at(
                line,
                column,
                key,
                format!("expected `{expected}`, got `{text}`"),
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tokens found line by line, as the reader first did: each line cut
    /// at `#`, split at whitespace, columns counted in characters.
    fn plain_tokens(text: &str) -> Vec<(String, usize, usize, usize)> {
        let mut out = Vec::new();
        let mut line_start = 0;
        for (l, line) in text.split('\n').enumerate() {
            let kept = line.split('#').next().unwrap_or("");
            let mut in_token = None;
            let chars = kept.char_indices().chain([(kept.len(), ' ')]);
            for (column, (i, c)) in chars.enumerate() {
                match (c.is_whitespace(), in_token) {
                    (false, None) => in_token = Some((i, column)),
                    (true, Some((start, at))) => {
                        out.push((kept[start..i].to_owned(), l + 1, at + 1, line_start + start));
                        in_token = None;
                    }
                    _ => {}
                }
            }
            line_start += line.len() + 1;
        }
        out
    }

    #[test]
    fn tokens_are_found_in_place_as_the_plain_line_by_line_reading_finds_them() {
        let text = "v\r\nfrom 1 2\t3 # a comment, # and more\r\n\u{e9}l\u{e8}ve\u{2003}4#5 6\n\n  \
                    at\u{a0}x\n# whole line\ns 1 2 3 0.5";
        let mut scanner = Scanner {
            text,
            pos: 0,
            line: 1,
            column: 0,
            counted_to: 0,
        };
        let found: Vec<_> = std::iter::from_fn(|| scanner.next())
            .map(|t| (t.text.to_owned(), t.line, t.column, t.offset))
            .collect();
        assert_eq!(found, plain_tokens(text));
        assert!(found.len() > 12, "{found:?}");
    }
}
