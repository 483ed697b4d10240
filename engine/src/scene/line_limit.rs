//! Text inputs read line by line (OBJ meshes) through [`LineLimit`], which
//! fails once a line grows past a bound, so that a file with no line
//! breaks — a corrupted multi-gigabyte OBJ, a binary file given by
//! mistake — is an error after a megabyte, not an attempt to hold the
//! whole file in one string.

use std::io::{self, BufRead, Read};

/// The longest line a text input may have (1 MiB; OBJ lines are tens of
/// bytes, a face of thousands of vertices a few tens of kilobytes).
pub const MAX_LINE: usize = 1 << 20;

/// A reader that fails once a line is longer than its limit, and
/// remembers where.
pub struct LineLimit<R> {
    inner: R,
    limit: usize,
    /// Bytes since the last line break.
    run: usize,
    /// Line breaks passed (the current line's number less one).
    lines: usize,
}

impl<R: BufRead> LineLimit<R> {
    /// Reads `inner` with lines of at most `limit` bytes.
    pub fn new(inner: R, limit: usize) -> Self {
        Self {
            inner,
            limit,
            run: 0,
            lines: 0,
        }
    }

    /// The 1-based number of the line that was too long, if one was.
    pub fn long_line(&self) -> Option<usize> {
        (self.run > self.limit).then_some(self.lines + 1)
    }
}

impl<R: BufRead> Read for LineLimit<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        let n = {
            let buf = self.fill_buf()?;
            let n = buf.len().min(out.len());
            out[..n].copy_from_slice(&buf[..n]);
            n
        };
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for LineLimit<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        if self.run > self.limit {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "line {} is longer than {} bytes",
                    self.lines + 1,
                    self.limit
                ),
            ));
        }
        self.inner.fill_buf()
    }

    fn consume(&mut self, n: usize) {
        // The bytes being consumed are still in the inner buffer.
        if let Ok(buf) = self.inner.fill_buf() {
            let chunk = &buf[..n.min(buf.len())];
            match chunk.iter().rposition(|&b| b == b'\n') {
                Some(last) => {
                    self.lines += chunk.iter().filter(|&&b| b == b'\n').count();
                    self.run = chunk.len() - last - 1;
                }
                None => self.run += chunk.len(),
            }
        }
        self.inner.consume(n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_lines_pass_and_a_long_one_is_named() {
        let text = "v 0 0 0\nv 1 0 0\n".to_string() + &"x".repeat(100) + "\nv 2 0 0\n";
        let mut ok = LineLimit::new(io::Cursor::new(text.clone()), 200);
        assert_eq!(ok.by_ref().lines().count(), 4);
        assert_eq!(ok.long_line(), None);
        let mut long = LineLimit::new(io::BufReader::with_capacity(16, io::Cursor::new(text)), 50);
        // Readers stop at the first error, as tobj does.
        let first_error = long.by_ref().lines().position(|l| l.is_err());
        assert_eq!(first_error, Some(2), "the long line must fail");
        assert_eq!(long.long_line(), Some(3));
    }
}
