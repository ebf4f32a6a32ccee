use super::*;

fn layout(seed: u64, ocean_fraction: f64, mountain_frequency: f64) -> Layout {
    let s = LayoutSettings { ocean_fraction, mountain_frequency, continent_scale_km: 1000.0, ..Default::default() };
    Layout::new(seed, &s)
}

/// Points of an `n × n` lattice with `spacing_m`, centred away from the calibration sample's
/// centre (and offset by a fraction of a cell so no point coincides with it).
fn lattice(n: i64, spacing_m: f64) -> impl Iterator<Item = (f64, f64)> {
    (0..n * n).map(move |i| {
        let (iy, ix) = ((i / n - n / 2) as f64 + 0.37, (i % n - n / 2) as f64 + 0.61);
        (3.1e6 + iy * spacing_m, -2.7e6 + ix * spacing_m)
    })
}

fn sorted(mut v: Vec<f32>) -> Vec<f32> {
    v.sort_by(f32::total_cmp);
    v
}

fn percentile(sorted: &[f32], u: f64) -> f32 {
    sorted[((sorted.len() - 1) as f64 * u).round() as usize]
}

#[test]
fn same_seed_gives_bit_identical_fields_over_overlapping_rects() {
    let (a, b, c) = (layout(42, 0.55, 1.0), layout(42, 0.55, 1.0), layout(43, 0.55, 1.0));
    let big = Rect::new(-40, -1000, 64, 80);
    let small = Rect::new(-10, -970, 20, 30);
    for px in [2_000.0, 30_000.0] {
        let (ea, eb) = (a.elevation(px), b.elevation(px));
        assert_eq!(ea.query(big).crop(small), eb.query(small));
        let (sa, sb) = (a.climate_sketch(px), b.climate_sketch(px));
        assert_eq!(sa.query(big).crop(small), sb.query(small));
        assert_ne!(c.elevation(px).query(small), eb.query(small), "another seed must differ");
    }
}

#[test]
fn land_fraction_follows_ocean_fraction() {
    for p in [0.3, 0.7] {
        let l = layout(7, p, 1.0);
        let points: Vec<_> = lattice(150, 250_000.0).collect();
        let land = points.iter().filter(|&&(y, x)| l.elevation_at(y, x) > 0.0).count();
        let f = land as f64 / points.len() as f64;
        println!("ocean fraction {p}: land fraction {f:.4}");
        assert!((f - (1.0 - p)).abs() < 0.05, "ocean fraction {p}: land fraction {f}");
    }
}

#[test]
fn elevations_follow_earth_like_hypsometry() {
    let l = layout(11, 0.55, 1.0);
    let all: Vec<f32> = lattice(120, 37_000.0).map(|(y, x)| l.elevation_at(y, x)).collect();
    assert!(all.iter().all(|&e| e != 0.0 && e.is_finite()), "land > 0 and sea < 0 strictly");
    let land = sorted(all.iter().copied().filter(|&e| e > 0.0).collect());
    let sea = sorted(all.iter().copied().filter(|&e| e < 0.0).collect());
    let median = percentile(&land, 0.5);
    let show = |v: &[f32]| [0.1, 0.5, 0.9, 0.99].map(|u| percentile(v, u));
    println!("land percentiles 10/50/90/99: {:?} m, sea: {:?} m", show(&land), show(&sea));
    assert!((150.0..900.0).contains(&median), "land median {median} m");
    assert!(percentile(&land, 0.99) > 2500.0, "land 99th percentile {} m", percentile(&land, 0.99));
    let sea_median = percentile(&sea, 0.5);
    assert!((-5200.0..-2500.0).contains(&sea_median), "sea median {sea_median} m");
}

#[test]
fn mountain_frequency_raises_the_highest_land() {
    let p99 = |f: f64| {
        let l = layout(5, 0.55, f);
        let land = sorted(lattice(100, 45_000.0).map(|(y, x)| l.elevation_at(y, x)).filter(|&e| e > 0.0).collect());
        percentile(&land, 0.99)
    };
    let (flat, steep) = (p99(0.0), p99(2.0));
    println!("99th percentile of land: {flat} m at frequency 0, {} m at 1, {steep} m at 2", p99(1.0));
    assert!(flat + 1000.0 < steep, "99th percentile of land: {flat} m without ranges, {steep} m at 2.0");
}

#[test]
fn far_coordinates_give_finite_values() {
    let l = layout(3, 0.55, 1.0);
    for (y, x) in [(3e7, 3e7), (-3e7, 3e7), (3e7, -3e7), (-3e7, -3e7), (4e7, -4e7)] {
        let e = l.elevation_at(y, x);
        let mut s = [0.0; sketch::CHANNELS];
        l.sketch_at(y, x, &mut s);
        assert!(e.is_finite() && e != 0.0 && s.iter().all(|v| v.is_finite()), "({y}, {x}): {e} {s:?}");
    }
    // Still varies at cell scale far away.
    let e: Vec<f32> = (0..16).map(|i| l.elevation_at(-3e7, -3e7 + i as f64 * 2000.0)).collect();
    assert!(e.windows(2).any(|w| w[0] != w[1]));
}

#[test]
fn continentality_is_zero_at_sea_and_high_deep_inland() {
    let l = layout(9, 0.55, 1.0);
    let r = 150_000.0;
    let ring = [(0.0, 0.0), (r, 0.0), (-r, 0.0), (0.0, r), (0.0, -r), (r, r), (-r, -r), (r, -r), (-r, r)];
    let (mut sea, mut inland) = (Vec::new(), Vec::new());
    for (y, x) in lattice(80, 120_000.0) {
        let e: Vec<f32> = ring.iter().map(|(dy, dx)| l.elevation_at(y + dy, x + dx)).collect();
        let mut s = [0.0; sketch::CHANNELS];
        l.sketch_at(y, x, &mut s);
        let cont = s[sketch::CONTINENTALITY];
        assert!((0.0..=1.0).contains(&cont));
        if e.iter().all(|&e| e < -3000.0) {
            sea.push(cont);
        } else if e.iter().all(|&e| e > 0.0) {
            inland.push(cont);
        }
    }
    assert!(sea.len() > 100 && inland.len() > 50, "{} deep-sea and {} inland points", sea.len(), inland.len());
    assert!(sea.iter().all(|&c| c == 0.0), "continentality over deep ocean");
    let mean = inland.iter().sum::<f32>() / inland.len() as f32;
    assert!(mean > 0.4, "mean continentality deep inland {mean}");
}

#[test]
fn climate_sketch_follows_the_zones() {
    let l = layout(13, 0.55, 1.0);
    let zone_m = l.settings().climate_zone_scale_km * 1000.0;
    let mean_temperature = |y: f64| {
        let mut sum = 0.0;
        for i in 0..200 {
            let mut s = [0.0; sketch::CHANNELS];
            l.sketch_at(y, i as f64 * 97_000.0, &mut s);
            sum += s[sketch::SEA_LEVEL_TEMPERATURE];
        }
        sum / 200.0
    };
    let (equator, pole, next_equator) =
        (mean_temperature(0.0), mean_temperature(zone_m), mean_temperature(2.0 * zone_m));
    assert!(equator > pole + 25.0 && next_equator > pole + 25.0, "{equator} {pole} {next_equator}");
}

/// `cargo test -p infiniterra-terrain --lib layout::tests::speed -- --ignored --nocapture`
#[test]
#[ignore]
fn speed() {
    let t = std::time::Instant::now();
    let l = Layout::new(1, &LayoutSettings::default());
    println!("Layout::new: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let t = std::time::Instant::now();
    let mut sum = 0.0;
    for (y, x) in lattice(300, 3_000.0) {
        sum += l.elevation_at(y, x);
    }
    println!("elevation_at: {:.2} µs/call ({sum})", t.elapsed().as_secs_f64() * 1e6 / 90_000.0);
    let t = std::time::Instant::now();
    let mut s = [0.0; sketch::CHANNELS];
    for (y, x) in lattice(300, 3_000.0) {
        l.sketch_at(y, x, &mut s);
    }
    println!("sketch_at: {:.2} µs/call", t.elapsed().as_secs_f64() * 1e6 / 90_000.0);
}

/// Writes maps to `$TMPDIR/layout_*.png` for eyeballing:
/// `cargo test -p infiniterra-terrain --lib layout::tests::render -- --ignored`
#[test]
#[ignore]
fn render() {
    let l = Layout::new(1, &LayoutSettings::default());
    let n = 512;
    for (name, px) in [("world", 16_000.0), ("zoom", 1_000.0)] {
        let e = l.elevation(px).query(Rect::new(-(n as i64) / 2, -(n as i64) / 2, n as i64, n as i64));
        let rgb: Vec<u8> = e.data.iter().flat_map(|&v| colour(v)).collect();
        let path = std::env::temp_dir().join(format!("layout_{name}.png"));
        std::fs::write(&path, png(n, n, &rgb)).expect("write png");
        println!("{}", path.display());
    }
    let s = l.climate_sketch(16_000.0).query(Rect::new(-(n as i64) / 2, -(n as i64) / 2, n as i64, n as i64));
    for (c, name, lo, hi) in
        [(0, "temperature", -25.0, 30.0), (2, "precipitation", 0.0, 2300.0), (3, "continentality", 0.0, 1.0)]
    {
        let rgb: Vec<u8> = s
            .channel(c)
            .iter()
            .flat_map(|&v| {
                let g = (((v - lo) / (hi - lo)).clamp(0.0, 1.0) * 255.0) as u8;
                [g, g, g]
            })
            .collect();
        std::fs::write(std::env::temp_dir().join(format!("layout_{name}.png")), png(n, n, &rgb)).expect("write png");
    }
}

fn colour(e: f32) -> [u8; 3] {
    let lerp = |a: [f32; 3], b: [f32; 3], t: f32| {
        let t = t.clamp(0.0, 1.0);
        [0, 1, 2].map(|i| (a[i] + t * (b[i] - a[i])) as u8)
    };
    if e < 0.0 {
        lerp([120.0, 170.0, 230.0], [10.0, 20.0, 80.0], -e / 6000.0)
    } else if e < 1000.0 {
        lerp([60.0, 140.0, 60.0], [200.0, 190.0, 110.0], e / 1000.0)
    } else {
        lerp([200.0, 190.0, 110.0], [255.0, 255.0, 255.0], (e - 1000.0) / 4000.0)
    }
}

/// A minimal uncompressed RGB PNG.
fn png(w: usize, h: usize, rgb: &[u8]) -> Vec<u8> {
    fn crc(data: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in data {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 { 0xedb8_8320 ^ (c >> 1) } else { c >> 1 };
            }
        }
        !c
    }
    fn chunk(out: &mut Vec<u8>, kind: &[u8], data: &[u8]) {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        out.extend_from_slice(&body);
        out.extend_from_slice(&crc(&body).to_be_bytes());
    }
    let mut raw = Vec::new();
    for row in rgb.chunks(w * 3) {
        raw.push(0);
        raw.extend_from_slice(row);
    }
    let mut z = vec![0x78, 0x01];
    let blocks: Vec<&[u8]> = raw.chunks(65_535).collect();
    for (i, b) in blocks.iter().enumerate() {
        z.push((i + 1 == blocks.len()) as u8);
        z.extend_from_slice(&(b.len() as u16).to_le_bytes());
        z.extend_from_slice(&(!(b.len() as u16)).to_le_bytes());
        z.extend_from_slice(b);
    }
    let (mut a, mut bb) = (1u32, 0u32);
    for &v in &raw {
        a = (a + v as u32) % 65_521;
        bb = (bb + a) % 65_521;
    }
    z.extend_from_slice(&((bb << 16) | a).to_be_bytes());
    let mut out = vec![0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&(w as u32).to_be_bytes());
    ihdr.extend_from_slice(&(h as u32).to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &z);
    chunk(&mut out, b"IEND", &[]);
    out
}
