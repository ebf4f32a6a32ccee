//! Rectangles on the infinite integer grid and dense multi-channel tiles over them.
//!
//! Coordinates are `i64` everywhere (y = south/z, x = east), so ±30,000,000 blocks and
//! anything derived from it never overflow. A [`Tile`] stores `channels × h × w` values
//! row-major (channel, then y, then x).

/// Floor division for a positive divisor (rounds toward −∞, unlike `/`).
pub fn div_floor(a: i64, b: i64) -> i64 {
    debug_assert!(b > 0);
    a.div_euclid(b)
}

/// Ceiling division for a positive divisor.
pub fn div_ceil(a: i64, b: i64) -> i64 {
    debug_assert!(b > 0);
    -(-a).div_euclid(b)
}

/// An axis-aligned rectangle `[y0, y0+h) × [x0, x0+w)` on the integer grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Rect {
    /// First row (inclusive).
    pub y0: i64,
    /// First column (inclusive).
    pub x0: i64,
    /// Number of rows (> 0 for a non-empty rectangle).
    pub h: i64,
    /// Number of columns.
    pub w: i64,
}

impl Rect {
    /// A rectangle from its top-left corner and size.
    pub const fn new(y0: i64, x0: i64, h: i64, w: i64) -> Rect {
        Rect { y0, x0, h, w }
    }

    /// One past the last row.
    pub const fn y1(&self) -> i64 {
        self.y0 + self.h
    }

    /// One past the last column.
    pub const fn x1(&self) -> i64 {
        self.x0 + self.w
    }

    /// Number of cells.
    pub fn area(&self) -> usize {
        (self.h.max(0) * self.w.max(0)) as usize
    }

    /// True when the rectangle holds no cell.
    pub fn is_empty(&self) -> bool {
        self.h <= 0 || self.w <= 0
    }

    /// The overlap of two rectangles, or `None` when they do not overlap.
    pub fn intersect(&self, other: &Rect) -> Option<Rect> {
        let y0 = self.y0.max(other.y0);
        let x0 = self.x0.max(other.x0);
        let y1 = self.y1().min(other.y1());
        let x1 = self.x1().min(other.x1());
        (y1 > y0 && x1 > x0).then(|| Rect::new(y0, x0, y1 - y0, x1 - x0))
    }

    /// True when `other` lies entirely inside `self`.
    pub fn contains_rect(&self, other: &Rect) -> bool {
        other.y0 >= self.y0 && other.x0 >= self.x0 && other.y1() <= self.y1() && other.x1() <= self.x1()
    }

    /// The rectangle grown by `m` cells on every side.
    pub fn pad(&self, m: i64) -> Rect {
        Rect::new(self.y0 - m, self.x0 - m, self.h + 2 * m, self.w + 2 * m)
    }

    /// The rectangle grown by different margins per side (top, bottom, left, right).
    pub fn pad_sides(&self, top: i64, bottom: i64, left: i64, right: i64) -> Rect {
        Rect::new(self.y0 - top, self.x0 - left, self.h + top + bottom, self.w + left + right)
    }
}

/// A dense block of `channels` values per cell of `rect`.
#[derive(Clone, Debug, PartialEq)]
pub struct Tile {
    /// Where the tile lies on the global grid.
    pub rect: Rect,
    /// Number of channels.
    pub channels: usize,
    /// `channels × h × w` values, channel-major then row-major.
    pub data: Vec<f32>,
}

impl Tile {
    /// A tile of zeros.
    pub fn zeros(channels: usize, rect: Rect) -> Tile {
        Tile { rect, channels, data: vec![0.0; channels * rect.area()] }
    }

    /// A tile from existing data; panics if the length does not match (a programming error).
    pub fn from_data(channels: usize, rect: Rect, data: Vec<f32>) -> Tile {
        assert_eq!(data.len(), channels * rect.area(), "tile data length does not match its shape");
        Tile { rect, channels, data }
    }

    /// Width in cells as `usize`.
    pub fn width(&self) -> usize {
        self.rect.w as usize
    }

    /// Height in cells as `usize`.
    pub fn height(&self) -> usize {
        self.rect.h as usize
    }

    /// One channel's plane.
    pub fn channel(&self, c: usize) -> &[f32] {
        let n = self.rect.area();
        &self.data[c * n..(c + 1) * n]
    }

    /// One channel's plane, mutable.
    pub fn channel_mut(&mut self, c: usize) -> &mut [f32] {
        let n = self.rect.area();
        &mut self.data[c * n..(c + 1) * n]
    }

    /// Value at global coordinates (panics outside the tile).
    pub fn get(&self, c: usize, y: i64, x: i64) -> f32 {
        let (ly, lx) = ((y - self.rect.y0) as usize, (x - self.rect.x0) as usize);
        assert!(ly < self.height() && lx < self.width(), "({y},{x}) outside tile {:?}", self.rect);
        self.data[(c * self.height() + ly) * self.width() + lx]
    }

    /// Value at local coordinates (row `ly`, column `lx` of the tile).
    pub fn at(&self, c: usize, ly: usize, lx: usize) -> f32 {
        self.data[(c * self.height() + ly) * self.width() + lx]
    }

    /// The part of the tile inside `rect` (which must lie inside the tile).
    pub fn crop(&self, rect: Rect) -> Tile {
        assert!(self.rect.contains_rect(&rect), "crop {rect:?} outside tile {:?}", self.rect);
        let mut out = Tile::zeros(self.channels, rect);
        let (w, ow) = (self.width(), rect.w as usize);
        let dy = (rect.y0 - self.rect.y0) as usize;
        let dx = (rect.x0 - self.rect.x0) as usize;
        for c in 0..self.channels {
            for y in 0..rect.h as usize {
                let src = (c * self.height() + dy + y) * w + dx;
                let dst = (c * rect.h as usize + y) * ow;
                out.data[dst..dst + ow].copy_from_slice(&self.data[src..src + ow]);
            }
        }
        out
    }

    /// A new tile holding only the listed channels, in that order.
    pub fn select(&self, channels: &[usize]) -> Tile {
        let mut data = Vec::with_capacity(channels.len() * self.rect.area());
        for &c in channels {
            data.extend_from_slice(self.channel(c));
        }
        Tile::from_data(channels.len(), self.rect, data)
    }

    /// Stack tiles over the same rectangle channel-wise.
    pub fn stack(tiles: &[&Tile]) -> Tile {
        let rect = tiles[0].rect;
        assert!(tiles.iter().all(|t| t.rect == rect), "stacked tiles must share a rectangle");
        let channels = tiles.iter().map(|t| t.channels).sum();
        let mut data = Vec::with_capacity(channels * rect.area());
        for t in tiles {
            data.extend_from_slice(&t.data);
        }
        Tile::from_data(channels, rect, data)
    }

    /// Bytes held by the tile's values.
    pub fn bytes(&self) -> usize {
        self.data.len() * std::mem::size_of::<f32>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_and_ceil_division_round_toward_the_right_infinity() {
        assert_eq!(div_floor(-1, 4), -1);
        assert_eq!(div_floor(-4, 4), -1);
        assert_eq!(div_floor(-5, 4), -2);
        assert_eq!(div_floor(7, 4), 1);
        assert_eq!(div_ceil(-5, 4), -1);
        assert_eq!(div_ceil(5, 4), 2);
        assert_eq!(div_ceil(8, 4), 2);
    }

    #[test]
    fn crop_takes_the_right_cells() {
        let r = Rect::new(-2, 10, 3, 4);
        let data: Vec<f32> = (0..24).map(|v| v as f32).collect();
        let t = Tile::from_data(2, r, data);
        let c = t.crop(Rect::new(-1, 11, 2, 2));
        assert_eq!(c.data, vec![5.0, 6.0, 9.0, 10.0, 17.0, 18.0, 21.0, 22.0]);
        assert_eq!(c.get(1, 0, 12), 22.0);
    }

    #[test]
    fn intersection_is_empty_for_touching_rectangles() {
        let a = Rect::new(0, 0, 4, 4);
        assert_eq!(a.intersect(&Rect::new(4, 0, 4, 4)), None);
        assert_eq!(a.intersect(&Rect::new(2, -1, 4, 2)), Some(Rect::new(2, 0, 2, 1)));
    }
}
