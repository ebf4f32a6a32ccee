//! Drainage of one padded window of the hydrology grid: depressions filled by a priority
//! flood, flow directions, lakes and their water balance, and discharge accumulated
//! downstream.
//!
//! Written by hand: the algorithms are short (Barnes, Lehman & Mulla 2014, "Priority-flood:
//! An optimal depression-filling and watershed-labeling algorithm", with its ε-variant so
//! flats drain) and no maintained crate runs them on our tiles with our tie-breaking, which
//! must be by position so that every window that holds a cell agrees on it.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// The eight neighbours (dy, dx), indexed by the direction codes [`Drainage::down`] stores.
pub const D8: [(i64, i64); 8] = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)];
/// No downstream neighbour: the sea, a sink, or the window's edge.
pub const NO_DOWN: i8 = -1;
/// Rise of the filled surface from one cell to the next across a flat or a filled
/// depression, metres: flats drain toward their outlet and a filled surface strictly falls
/// downstream.
const EPSILON_M: f32 = 1e-3;
/// Where a filled depression is this many metres deep or more it is a lake (or, in a basin
/// too dry to fill, a dry lake bed). Shallower filling is a flat that drains: a 1 km grid's
/// pits of a few metres are mostly the relief's noise, and as lakes they covered a tenth of
/// wet lowlands and dry beds a fifth of deserts; at 10 m lakes still held 10.6 % of the land
/// of an inland region at the block grid (real land: 1.8 %, HydroLAKES). 25 m is one block of
/// the default vertical scale: a shallower basin would be at most one block deep.
pub const LAKE_MIN_DEPTH_M: f32 = 25.0;
/// Seconds in a year (discharge is m³/s, climate mm/yr).
pub const SECONDS_PER_YEAR: f64 = 365.25 * 86_400.0;

/// What a cell is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Kind {
    /// Land that drains.
    Land = 0,
    /// The sea (elevation below 0).
    Sea = 1,
    /// A lake: a filled depression whose inflow makes up for its evaporation.
    Lake = 2,
    /// A dry lake bed: a depression too dry to fill (an endorheic sink).
    Dry = 3,
}

impl Kind {
    /// The kind stored as `code` (as a float channel holds it).
    pub fn from_code(code: f32) -> Kind {
        match code.round() as i32 {
            1 => Kind::Sea,
            2 => Kind::Lake,
            3 => Kind::Dry,
            _ => Kind::Land,
        }
    }
}

/// The climate and elevation of every cell of a window, row-major.
pub struct Inputs<'a> {
    /// Rows and columns.
    pub h: usize,
    /// Columns.
    pub w: usize,
    /// Size of a cell, metres.
    pub cell_m: f64,
    /// Elevation, metres.
    pub elevation: &'a [f32],
    /// Annual precipitation, mm.
    pub precipitation: &'a [f32],
    /// Annual mean temperature, °C.
    pub temperature: &'a [f32],
    /// Water flowing in at each cell from beyond the window, m³/s (a river the continent's
    /// drainage brings in), added to the cell's own runoff.
    pub inflow: Option<&'a [f32]>,
    /// Metres the water must rise at each cell of the window's edge before it leaves there
    /// (row-major like the rest; only edge cells are read): where the continent's own
    /// drainage says the window's edge lies in a closed basin, the edge is no free outlet.
    pub edge_rise: Option<&'a [f32]>,
}

/// The drainage of a window, row-major like its inputs.
pub struct Drainage {
    /// Direction code (index into [`D8`]) of each cell's downstream neighbour, or [`NO_DOWN`].
    pub down: Vec<i8>,
    /// Discharge leaving each cell, m³/s (the cell's own runoff and everything upstream).
    pub discharge: Vec<f32>,
    /// Water level, metres: the filled surface on land (never rising downstream), the
    /// spill level of a lake or dry lake, 0 at sea.
    pub level: Vec<f32>,
    /// What each cell is.
    pub kind: Vec<Kind>,
    /// The filled surface, metres: the elevation, raised over depressions and flats to
    /// [`EPSILON_M`] above the cell it drains to, so it strictly falls along every path.
    pub filled: Vec<f32>,
}

/// Potential evapotranspiration, mm/yr, at a mean temperature (a Thornthwaite-like ramp:
/// ≈ 300 mm at 0 °C, 1,550 mm at 25 °C).
pub fn potential_evaporation_mm(temperature_c: f32) -> f64 {
    (300.0 + 50.0 * f64::from(temperature_c)).clamp(150.0, 2000.0)
}

/// Runoff, mm/yr, of a cell with `precipitation_mm` at `temperature_c`: Fu's form of the
/// Budyko curve (ω = 2.6), the share of rain that evaporation leaves to the rivers.
pub fn runoff_mm(precipitation_mm: f32, temperature_c: f32) -> f64 {
    let p = f64::from(precipitation_mm.max(0.0));
    if p <= 0.0 {
        return 0.0;
    }
    let aridity = potential_evaporation_mm(temperature_c) / p;
    const OMEGA: f64 = 2.6;
    let evaporated = 1.0 + aridity - (1.0 + aridity.powf(OMEGA)).powf(1.0 / OMEGA);
    (p * (1.0 - evaporated)).max(0.0)
}

/// A cell waiting in the flood: ordered by filled height, then by position (lowest first).
#[derive(Clone, Copy, PartialEq)]
struct Wet {
    height: f32,
    index: usize,
}

impl Eq for Wet {}

impl Ord for Wet {
    fn cmp(&self, other: &Self) -> Ordering {
        // BinaryHeap pops the greatest: reverse both keys.
        other.height.total_cmp(&self.height).then(other.index.cmp(&self.index))
    }
}

impl PartialOrd for Wet {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// No lake: a cell the flood did not fill.
const NONE: usize = usize::MAX;

/// A window flooded from its outlets (the sea and the edge).
struct Flood {
    /// The filled surface.
    filled: Vec<f32>,
    /// Direction codes, as [`Drainage::down`].
    down: Vec<i8>,
    /// Sea or land (lakes are decided later, by water balance).
    kind: Vec<Kind>,
    /// The depression each filled cell belongs to (the index of the cell the flood entered
    /// it by), or [`NONE`].
    lake: Vec<usize>,
    /// As [`Drainage::level`].
    level: Vec<f32>,
    /// Cells in the order the flood reached them: every cell after its downstream neighbour.
    order: Vec<usize>,
}

/// The priority flood (Barnes et al. 2014, ε-variant) of a `h` × `w` window of elevations
/// `e`, its edge cells raised by `edge_rise`.
fn flood(h: usize, w: usize, e: &[f32], edge_rise: Option<&[f32]>) -> Flood {
    let n = h * w;
    let mut filled = e.to_vec();
    let mut down = vec![NO_DOWN; n];
    let mut kind = vec![Kind::Land; n];
    let mut lake = vec![NONE; n];
    let mut level = e.to_vec();
    let mut seen = vec![false; n];
    let mut heap = BinaryHeap::new();
    for i in 0..n {
        let (y, x) = (i / w, i % w);
        let edge = y == 0 || x == 0 || y == h - 1 || x == w - 1;
        if e[i] < 0.0 {
            kind[i] = Kind::Sea;
            level[i] = 0.0;
        } else if edge {
            // A raised edge cell is the edge of a basin the window only partly holds: it and
            // what the flood fills from it are one depression at its height.
            let rise = edge_rise.map_or(0.0, |r| r[i].max(0.0));
            if rise > 0.0 {
                filled[i] = e[i] + rise;
                level[i] = filled[i];
                lake[i] = i;
            }
        } else {
            continue;
        }
        seen[i] = true;
        heap.push(Wet { height: filled[i], index: i });
    }
    let mut order = Vec::with_capacity(n);
    while let Some(Wet { index: c, .. }) = heap.pop() {
        order.push(c);
        let (cy, cx) = ((c / w) as i64, (c % w) as i64);
        for (d, &(dy, dx)) in D8.iter().enumerate() {
            let (ny, nx) = (cy + dy, cx + dx);
            if ny < 0 || nx < 0 || ny >= h as i64 || nx >= w as i64 {
                continue;
            }
            let m = ny as usize * w + nx as usize;
            if seen[m] {
                continue;
            }
            seen[m] = true;
            // The neighbour drains into c: its direction code points back at c.
            down[m] = (7 - d) as i8;
            if e[m] <= filled[c] {
                filled[m] = filled[c] + EPSILON_M;
                if lake[c] != NONE {
                    lake[m] = lake[c];
                    level[m] = level[c];
                } else {
                    lake[m] = m;
                    level[m] = filled[c].max(0.0);
                }
            } else {
                level[m] = e[m];
            }
            heap.push(Wet { height: filled[m], index: m });
        }
    }
    Flood { filled, down, kind, lake, level, order }
}

/// A window with its depressions breached ([`breach`]).
pub struct Breach {
    /// Metres each cell is cut down.
    pub lower: Vec<f32>,
    /// The carved surface, metres: strictly falls along `down` (a closed basin's cells stand
    /// at its filled surface).
    pub carved: Vec<f32>,
    /// Direction code of each cell's downstream neighbour on the carved surface, or
    /// [`NO_DOWN`].
    pub down: Vec<i8>,
    /// Cells in the order the flood reached them: every cell after its downstream neighbour.
    pub order: Vec<usize>,
}

/// Least fall of the carved surface from a cell to the next downstream, metres: a river cut
/// through a basin's rim, or run across a flat, keeps a slope the finer grids resolve (at
/// [`EPSILON_M`] per coarse cell a trunk river burned into the network lay flat for tens of
/// kilometres, and windows draining it from different ends disagreed on its direction).
const BREACH_FALL_M: f32 = 0.1;

/// Below this a depression is filled, not breached, metres: carving a path back to the
/// outlet for every pit of a few centimetres would walk whole flats again and again.
const MIN_BREACH_M: f32 = 0.5;

/// Metres each cell of a `h` × `w` window is lowered when every depression is breached
/// rather than filled: a channel is cut from its lowest point back through its rim, the way
/// a lake's outlet erodes until the lake drains. Cells `closed` (a dry basin, as its filled
/// surface `filled` says) keep their water and are not cut into.
///
/// A priority flood on the carved surface (Soille 2004's carving): the flood descends into a
/// depression as soon as it reaches it, and each cell found below the surface it was reached
/// from lowers the path it drains by to just under it. The carved surface falls at least
/// [`BREACH_FALL_M`] a cell along every path (raised over flats where it must).
pub fn breach(h: usize, w: usize, e: &[f32], filled: &[f32], closed: &[bool]) -> Breach {
    let n = h * w;
    let z: Vec<f32> = (0..n).map(|i| if closed[i] { filled[i].max(e[i]) } else { e[i] }).collect();
    let mut carved = z.clone();
    let mut down = vec![NONE; n];
    let mut code = vec![NO_DOWN; n];
    let mut order = Vec::with_capacity(n);
    let mut seen = vec![false; n];
    let mut heap = BinaryHeap::new();
    for i in 0..n {
        let (y, x) = (i / w, i % w);
        if e[i] < 0.0 || y == 0 || x == 0 || y == h - 1 || x == w - 1 {
            seen[i] = true;
            heap.push(Wet { height: z[i], index: i });
        }
    }
    while let Some(Wet { index: c, .. }) = heap.pop() {
        order.push(c);
        let (cy, cx) = ((c / w) as i64, (c % w) as i64);
        for (d, &(dy, dx)) in D8.iter().enumerate() {
            let (ny, nx) = (cy + dy, cx + dx);
            if ny < 0 || nx < 0 || ny >= h as i64 || nx >= w as i64 {
                continue;
            }
            let m = ny as usize * w + nx as usize;
            if seen[m] {
                continue;
            }
            seen[m] = true;
            down[m] = c;
            code[m] = (7 - d) as i8;
            if z[m] >= carved[c] + BREACH_FALL_M {
                carved[m] = z[m];
            } else if carved[c] - z[m] < MIN_BREACH_M || closed[m] {
                carved[m] = carved[c] + BREACH_FALL_M;
            } else {
                carved[m] = z[m];
                let (mut target, mut k) = (z[m] - BREACH_FALL_M, c);
                while k != NONE && carved[k] > target {
                    carved[k] = target;
                    target -= BREACH_FALL_M;
                    k = down[k];
                }
            }
            heap.push(Wet { height: carved[m], index: m });
        }
    }
    let lower = (0..n).map(|i| (e[i] - carved[i]).max(0.0)).collect();
    Breach { lower, carved, down: code, order }
}

/// Drains a window. The sea and the window's edge are the outlets; every other cell drains
/// to one of them or into a dry lake bed.
pub fn drain(input: &Inputs) -> Drainage {
    let n = input.h * input.w;
    let w = input.w;
    let e = input.elevation;
    let Flood { filled, down, mut kind, lake, level, order } = flood(input.h, w, e, input.edge_rise);

    let area = input.cell_m * input.cell_m;
    let runoff: Vec<f64> = (0..n)
        .map(|i| {
            if kind[i] == Kind::Sea {
                0.0
            } else {
                runoff_mm(input.precipitation[i], input.temperature[i]) / 1000.0 * area / SECONDS_PER_YEAR
                    + input.inflow.map_or(0.0, |q| f64::from(q[i]))
            }
        })
        .collect();
    let deep = |i: usize| lake[i] != NONE && level[i] - e[i] >= LAKE_MIN_DEPTH_M;

    // Each lake's water balance: its inflow against the evaporation from its surface beyond
    // the rain on it. The entry cell is reached first, so, walking upstream-first, all of a
    // lake's cells and everything draining into them are summed when it comes.
    let mut discharge = vec![0.0f64; n];
    let mut surface = vec![0.0f64; n];
    let mut wet = vec![false; n];
    for &c in order.iter().rev() {
        discharge[c] += runoff[c];
        if deep(c) {
            let deficit = potential_evaporation_mm(input.temperature[c]) - f64::from(input.precipitation[c]);
            surface[lake[c]] += deficit.max(0.0) / 1000.0 * area / SECONDS_PER_YEAR;
        }
        if lake[c] == c {
            // The entry: everything the lake gets has arrived. A dry lake's water evaporates
            // and nothing flows on.
            wet[c] = discharge[c] >= surface[c];
            if !wet[c] {
                continue;
            }
        }
        if down[c] != NO_DOWN {
            let (dy, dx) = D8[down[c] as usize];
            let m = ((c / w) as i64 + dy) as usize * w + ((c % w) as i64 + dx) as usize;
            discharge[m] += discharge[c];
        }
    }
    for (i, k) in kind.iter_mut().enumerate() {
        match lake.get(i).copied().filter(|&l| l != NONE) {
            // Every cell of a dry basin is its bed: water reaching it ends there.
            Some(l) if !wet[l] => *k = Kind::Dry,
            Some(_) if deep(i) => *k = Kind::Lake,
            _ => {}
        }
    }
    Drainage { down, discharge: discharge.into_iter().map(|q| q as f32).collect(), level, kind, filled }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(h: usize, w: usize, elevation: &[f32], precipitation: f32) -> Drainage {
        let n = h * w;
        drain(&Inputs {
            h,
            w,
            cell_m: 1000.0,
            elevation,
            precipitation: &vec![precipitation; n],
            temperature: &vec![10.0; n],
            inflow: None,
            edge_rise: None,
        })
    }

    fn downstream(d: &Drainage, w: usize, i: usize) -> Option<usize> {
        (d.down[i] != NO_DOWN).then(|| {
            let (dy, dx) = D8[d.down[i] as usize];
            ((i / w) as i64 + dy) as usize * w + ((i % w) as i64 + dx) as usize
        })
    }

    #[test]
    fn budyko_runoff_is_a_growing_share_of_rain_and_evaporation_grows_with_warmth() {
        assert_eq!(runoff_mm(0.0, 20.0), 0.0);
        let (dry, wet) = (runoff_mm(300.0, 15.0), runoff_mm(2000.0, 15.0));
        assert!(dry < 0.1 * 300.0 && wet > 0.4 * 2000.0, "{dry} {wet}");
        assert!(runoff_mm(800.0, 0.0) > runoff_mm(800.0, 25.0));
    }

    #[test]
    fn a_valley_drains_to_the_sea_with_discharge_growing_and_level_falling_downstream() {
        // A V-shaped valley falling west to a sea in column 0.
        let (h, w) = (9, 12);
        let e: Vec<f32> = (0..h * w)
            .map(|i| {
                let (y, x) = ((i / w) as f32, (i % w) as f32);
                if x < 1.0 {
                    -50.0
                } else {
                    x * 20.0 + (y - 4.0).abs() * 30.0
                }
            })
            .collect();
        let d = run(h, w, &e, 1500.0);
        // From the head of the valley downstream to the sea.
        let mut i = 4 * w + 10;
        let mut steps = 0;
        while d.kind[i] != Kind::Sea {
            let next = downstream(&d, w, i).expect("land drains somewhere");
            assert!(d.level[next] <= d.level[i], "level rises at {next}");
            assert!(d.discharge[next] >= d.discharge[i] || d.kind[next] == Kind::Sea);
            i = next;
            steps += 1;
        }
        assert!(steps >= 9, "{steps}");
        assert!(d.discharge[4 * w + 1] > 5.0 * d.discharge[4 * w + 9]);
    }

    #[test]
    fn a_closed_basin_fills_to_its_spill_level_where_wet_and_stays_dry_where_arid() {
        let (h, w, e) = bowl();
        let wet = run(h, w, &e, 2500.0);
        let centre = 5 * w + 5;
        assert_eq!(wet.kind[centre], Kind::Lake);
        assert_eq!(wet.level[centre], 200.0, "the lake stands at its notch");
        for i in 0..h * w {
            if wet.kind[i] == Kind::Lake {
                assert_eq!(wet.level[i], 200.0, "one level for the whole lake");
            }
        }
        // The outlet carries the lake's water on.
        let notch = 5 * w + 8;
        assert!(wet.discharge[notch] > wet.discharge[centre]);
        let dry = run(h, w, &e, 120.0);
        assert_eq!(dry.kind[centre], Kind::Dry);
        assert!(dry.discharge[notch] < dry.discharge[centre] + 1e-6, "nothing leaves a dry basin");
    }

    /// A bowl (centre 100 m) in a rim at 300 m with a notch at 200 m on the east side; outside
    /// the rim a slope down to the window's edge.
    fn bowl() -> (usize, usize, Vec<f32>) {
        let (h, w) = (11, 11);
        let e = (0..h * w)
            .map(|i| {
                let (y, x) = ((i / w) as i64 - 5, (i % w) as i64 - 5);
                let r = y.abs().max(x.abs());
                match r {
                    0..=2 => 100.0 + 10.0 * r as f32,
                    3 if y == 0 && x == 3 => 200.0,
                    3 => 300.0,
                    _ => 150.0 - 10.0 * r as f32,
                }
            })
            .collect();
        (h, w, e)
    }

    #[test]
    fn a_breached_basin_drains_through_a_cut_in_its_rim_and_a_closed_one_is_not_cut() {
        let (h, w, e) = bowl();
        let fill = run(h, w, &e, 2500.0).filled;
        let lower = breach(h, w, &e, &fill, &vec![false; h * w]).lower;
        assert!(lower.iter().all(|&l| l >= 0.0));
        let carved: Vec<f32> = e.iter().zip(&lower).map(|(e, l)| e - l).collect();
        // The carved surface has no pit: every cell has a lower neighbour or is on the edge.
        for i in 0..h * w {
            let (y, x) = ((i / w) as i64, (i % w) as i64);
            if y == 0 || x == 0 || y == h as i64 - 1 || x == w as i64 - 1 {
                continue;
            }
            let lowest = D8
                .iter()
                .map(|&(dy, dx)| carved[((y + dy) * w as i64 + x + dx) as usize])
                .fold(f32::INFINITY, f32::min);
            assert!(lowest < carved[i], "pit at ({y}, {x}): {}", carved[i]);
        }
        // The cut runs through the notch, down to the bowl's floor; the rest of the rim stands.
        let notch = 5 * w + 8;
        assert!(carved[notch] < 100.0, "{}", carved[notch]);
        assert_eq!(lower[2 * w + 2], 0.0, "the rim's corner is not cut");
        assert!(lower.iter().filter(|&&l| l > 0.0).count() <= 6, "{lower:?}");
        // A closed (dry) basin keeps its rim.
        let closed: Vec<bool> = (0..h * w).map(|i| fill[i] > e[i]).collect();
        let kept = breach(h, w, &e, &fill, &closed).lower;
        assert_eq!(kept[notch], 0.0);
    }

    #[test]
    fn a_raised_window_edge_holds_the_water_back_as_a_lake() {
        // A valley falling east to the window's edge: free, it drains out there; with the edge
        // raised 40 m (the continent says the valley runs into a closed basin), its lower end
        // is a lake at the raised height.
        let (h, w) = (7, 12);
        let e: Vec<f32> = (0..h * w)
            .map(|i| {
                let (y, x) = ((i / w) as f32, (i % w) as f32);
                300.0 - 10.0 * x + 40.0 * (y - 3.0).abs()
            })
            .collect();
        let free = run(h, w, &e, 1500.0);
        assert!(free.kind.iter().all(|&k| k == Kind::Land));
        let rise = vec![40.0; h * w];
        let held = drain(&Inputs {
            h,
            w,
            cell_m: 1000.0,
            elevation: &e,
            precipitation: &vec![1500.0; h * w],
            temperature: &vec![10.0; h * w],
            inflow: None,
            edge_rise: Some(&rise),
        });
        let end = 3 * w + (w - 2);
        assert_eq!(held.kind[end], Kind::Lake, "{:?}", held.kind);
        assert!((held.level[end] - (e[3 * w + w - 1] + 40.0)).abs() < 0.01, "{}", held.level[end]);
    }

    #[test]
    fn flats_drain_and_every_cell_reaches_an_outlet() {
        let (h, w) = (16, 16);
        let e = vec![50.0f32; h * w];
        let d = run(h, w, &e, 800.0);
        for start in 0..h * w {
            let (mut i, mut steps) = (start, 0);
            while let Some(next) = downstream(&d, w, i) {
                i = next;
                steps += 1;
                assert!(steps < h * w, "loop from {start}");
            }
            let (y, x) = (i / w, i % w);
            assert!(y == 0 || x == 0 || y == h - 1 || x == w - 1, "ends inside at {i}");
        }
    }
}
