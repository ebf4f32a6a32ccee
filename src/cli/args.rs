//! Argument types shared by several subcommands.

use std::str::FromStr;

/// A size in blocks, written `W` (square) or `WxH`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Width (x), blocks.
    pub width: i64,
    /// Height (z), blocks.
    pub height: i64,
}

impl FromStr for Size {
    type Err = String;

    fn from_str(s: &str) -> Result<Size, String> {
        let parse = |v: &str| -> Result<i64, String> {
            let n: i64 = v.trim().parse().map_err(|_| format!("{v:?} is not a whole number of blocks"))?;
            if (1..=1_000_000).contains(&n) {
                Ok(n)
            } else {
                Err(format!("{n} is out of range (allowed 1..=1000000 blocks)"))
            }
        };
        match s.split_once(['x', 'X']) {
            Some((w, h)) => Ok(Size { width: parse(w)?, height: parse(h)? }),
            None => parse(s).map(|n| Size { width: n, height: n }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_square_and_rectangular() {
        assert_eq!("512".parse::<Size>(), Ok(Size { width: 512, height: 512 }));
        assert_eq!("640x480".parse::<Size>(), Ok(Size { width: 640, height: 480 }));
        assert!("0".parse::<Size>().unwrap_err().contains("out of range"));
        assert!("12xabc".parse::<Size>().unwrap_err().contains("\"abc\""));
    }
}
