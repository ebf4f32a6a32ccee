use super::*;

fn field(filter: &ErosionFilter, slope: f64, gradient: (f64, f64), octaves: Range<u32>) -> Vec<f64> {
    (0..64)
        .flat_map(|i| (0..64).map(move |j| (i as f64 * 37.0, j as f64 * 37.0)))
        .map(|(z, x)| filter.apply(x, z, slope, gradient, octaves.clone()).height)
        .collect()
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|h| h * h).sum::<f64>() / v.len() as f64).sqrt()
}

#[test]
fn the_same_point_gives_the_same_bits_and_seeds_differ() {
    let (a, b) = (ErosionFilter::new(7), ErosionFilter::new(8));
    let at = |f: &ErosionFilter| f.apply(12_345.5, -987_654.25, 0.2, (0.1, -0.15), 0..8);
    assert_eq!(at(&a).height.to_bits(), at(&ErosionFilter::new(7)).height.to_bits());
    assert_ne!(at(&a).height, at(&b).height);
    // Far from the origin the lattice still hashes and the values stay bounded.
    let far = a.apply(7.5e9, -7.5e9, 0.3, (0.2, 0.2), 0..8);
    assert!(far.height.is_finite() && far.height.abs() < 2_000.0, "{far:?}");
}

#[test]
fn octave_bands_split_the_ladder_without_gap_or_overlap() {
    // The model grid (4 blocks) takes wavelengths of 4 grid pixels and more, blocks the rest
    // down to 2 blocks.
    for block in [15.0, 40.0, 125.0, 250.0] {
        let grid = octaves_between(SHORTEST_ON_GRID_PIXELS * 4.0 * block, f64::INFINITY);
        let blocks = octaves_between(2.0 * block, SHORTEST_ON_GRID_PIXELS * 4.0 * block);
        assert_eq!(grid.start, 0);
        assert_eq!(grid.end, blocks.start, "{block} m/block");
        assert!(wavelength(blocks.end - 1) >= 2.0 * block);
        assert!(blocks.end == MAX_OCTAVES || wavelength(blocks.end) < 2.0 * block);
        // Octaves halve: log2(shortest on the grid / 2 blocks) of them on the blocks.
        let below = (SHORTEST_ON_GRID_PIXELS * 4.0 / 2.0).log2().round() as usize;
        assert_eq!(blocks.len(), below, "octaves from 2 blocks to the grid's shortest at {block} m/block");
    }
}

#[test]
fn steep_relief_is_carved_deeper_than_plains() {
    let f = ErosionFilter::new(1);
    let plain = rms(&field(&f, 0.001, (0.001, 0.0), 0..6));
    let hills = rms(&field(&f, 0.1, (0.1, 0.0), 0..6));
    let mountains = rms(&field(&f, 0.5, (0.5, 0.0), 0..6));
    assert!(plain < 15.0, "plains keep a few metres: {plain}");
    assert!(hills > 4.0 * plain && mountains > 2.5 * hills, "{plain} {hills} {mountains}");
    // Less than in proportion to the slope (5× steeper): hillslopes stop steepening.
    assert!(mountains < 4.0 * hills, "{hills} {mountains}");
}

#[test]
fn gullies_run_downhill() {
    // One octave on a slope falling to +x: the height changes far less along the flow than
    // across it (the stripes' crests and troughs run downhill).
    let f = ErosionFilter::new(3);
    let k = 3;
    let lag = wavelength(k) / 8.0;
    let h = |x: f64, z: f64| f.apply(x, z, 0.2, (-0.2, 0.0), k..k + 1).height;
    let (mut along, mut across) = (0.0, 0.0);
    for i in 0..40 {
        for j in 0..40 {
            let (x, z) = (i as f64 * 61.0, j as f64 * 59.0);
            along += (h(x + lag, z) - h(x, z)).powi(2);
            across += (h(x, z + lag) - h(x, z)).powi(2);
        }
    }
    assert!(across > 4.0 * along, "across {across} along {along}");
}

#[test]
fn the_carving_is_continuous_across_every_octave_s_lattice_lines() {
    // Straight across the cell lines of each octave's lattice, a hair to either side: the
    // height must not step (a kernel whose tail is cut at the neighbourhood's edge would leave
    // steps of a per cent of the octave's amplitude, drawn as straight lines in a hillshade).
    let filter = ErosionFilter::new(3);
    let (slope, gradient) = (0.3, (0.2, -0.2));
    for k in 0..6 {
        let lambda = wavelength(k);
        let amp = amplitude(k, slope);
        // A point given in the octave's (turned) lattice frame, in world metres.
        let (sin, cos) = (f64::from(k) * GOLDEN_ANGLE + LATTICE_ANGLE).sin_cos();
        let world = |a: f64, b: f64| ((cos * a + sin * b) * lambda, (-sin * a + cos * b) * lambda);
        let at = |(x, z): (f64, f64)| filter.apply(x, z, slope, gradient, k..k + 1).height;
        let eps = 1e-7;
        for n in -20..20 {
            let line = f64::from(n);
            for along in [0.13, 0.37, 0.71] {
                let other = f64::from(n) + along;
                let step_a = (at(world(line + eps, other)) - at(world(line - eps, other))).abs();
                let step_b = (at(world(other, line + eps)) - at(world(other, line - eps))).abs();
                let step = step_a.max(step_b);
                assert!(step < 1e-4 * amp, "octave {k}: a step of {step} m on a lattice line");
            }
        }
    }
}

#[test]
fn remembering_the_lattice_changes_no_bit_in_any_visiting_order() {
    let filter = ErosionFilter::new(41);
    // Rows of neighbouring columns (mostly the same cells), then jumps between far places
    // and back (the remembered cells go stale), each visited with one shared lattice.
    let mut points: Vec<(f64, f64)> = (0..400).map(|i| (f64::from(i % 40) * 40.0, f64::from(i / 40) * 40.0)).collect();
    points
        .extend((0..200).map(|i| if i % 2 == 0 { (-3.0e6 + f64::from(i), 2.0e5) } else { (f64::from(i) * 13.0, 7.0) }));
    let mut lattice = Lattice::default();
    for (n, &(x, z)) in points.iter().enumerate() {
        let gradient = (0.05 * (n as f64 * 0.3).sin(), 0.05 * (n as f64 * 0.7).cos());
        let fresh = filter.apply(x, z, 0.2, gradient, 0..10);
        let remembered = filter.apply_with(&mut lattice, x, z, 0.2, gradient, 0..10);
        assert_eq!(fresh.height.to_bits(), remembered.height.to_bits(), "height at ({x}, {z})");
        assert_eq!(fresh.gradient.0.to_bits(), remembered.gradient.0.to_bits());
        assert_eq!(fresh.gradient.1.to_bits(), remembered.gradient.1.to_bits());
    }
    // Another seed through the same lattice: its points are its own.
    let other = ErosionFilter::new(42);
    let (x, z) = points[399];
    assert_eq!(other.apply(x, z, 0.2, (0.1, 0.0), 0..10), other.apply_with(&mut lattice, x, z, 0.2, (0.1, 0.0), 0..10));
}

/// The gully noise as first written: the points within reach gathered first, then only their
/// trigonometry, with the rounding by conversion to `i64` — what the world's pinned hashes
/// were recorded with.
fn gullies_gathered(points: &[(f64, f64); 16], fx: f64, fz: f64, dir: (f64, f64)) -> Gully {
    fn sin_cos_i64(t: f64) -> (f64, f64) {
        let r = t - ((t + 1024.5) as i64 - 1024) as f64;
        let quarter = (4.0 * r + 4.5) as i64 - 4;
        let a = TAU * (r - 0.25 * quarter as f64);
        let a2 = a * a;
        let s = a
            * (1.0
                + a2 * (-1.0 / 6.0
                    + a2 * (1.0 / 120.0
                        + a2 * (-1.0 / 5040.0
                            + a2 * (1.0 / 362_880.0 + a2 * (-1.0 / 39_916_800.0 + a2 / 6_227_020_800.0))))));
        let c = 1.0
            + a2 * (-0.5
                + a2 * (1.0 / 24.0
                    + a2 * (-1.0 / 720.0 + a2 * (1.0 / 40_320.0 + a2 * (-1.0 / 3_628_800.0 + a2 / 479_001_600.0)))));
        let m = (quarter & 3) as u64;
        let swap = (m & 1).wrapping_neg();
        let (sb, cb) = (s.to_bits(), c.to_bits());
        let s = ((sb & !swap) | (cb & swap)) ^ ((m & 2) << 62);
        let c = ((cb & !swap) | (sb & swap)) ^ (((m + 1) & 2) << 62);
        (f64::from_bits(s), f64::from_bits(c))
    }
    let across = (-dir.1, dir.0);
    let (mut phase, mut weight) = ([0.0f64; 16], [0.0f64; 16]);
    let mut kept = 0;
    for (n, &(jx, jz)) in points.iter().enumerate() {
        let (i, j) = ((n % 4) as f64 - 1.0, (n / 4) as f64 - 1.0);
        let (ox, oz) = (fx - (i + 0.5 * jx), fz - (j + 0.5 * jz));
        let r2 = ox * ox + oz * oz;
        phase[kept] = ox * across.0 + oz * across.1;
        weight[kept] = (1.0 - r2 / (REACH * REACH)).powi(4);
        kept += usize::from(r2 < REACH * REACH);
    }
    let (mut value, mut dx, mut dz, mut total) = (0.0, 0.0, 0.0, 0.0);
    for (&p, &w) in phase[..kept].iter().zip(&weight[..kept]) {
        let (s, c) = sin_cos_i64(p);
        value += c * w;
        dx -= s * TAU * across.0 * w;
        dz -= s * TAU * across.1 * w;
        total += w;
    }
    Gully { value: value / total, dx: dx / total, dz: dz / total }
}

#[test]
fn the_vectorised_gullies_are_the_gathered_ones_bit_for_bit() {
    let mut h = 7u64;
    let mut unit = move || {
        h = splitmix(h);
        (h >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..20_000 {
        let points: [(f64, f64); 16] = std::array::from_fn(|_| (unit(), unit()));
        let (fx, fz) = (unit(), unit());
        let angle = TAU * unit();
        let dir = (angle.cos(), angle.sin());
        let (a, b) = (gullies(&points, fx, fz, dir), gullies_gathered(&points, fx, fz, dir));
        for (x, y) in [(a.value, b.value), (a.dx, b.dx), (a.dz, b.dz)] {
            assert_eq!(x.to_bits(), y.to_bits(), "at ({fx}, {fz}) towards {dir:?}");
        }
        // Both paths of the dispatch, whichever this processor takes.
        let any = gullies_with(&points, fx, fz, dir, sin_cos_turns);
        assert_eq!((any.value.to_bits(), any.dx.to_bits()), (a.value.to_bits(), a.dx.to_bits()));
    }
}

#[test]
fn gentle_land_falls_off_faster_below_the_pivot_and_steep_land_keeps_the_hurst_law() {
    let plain = |k: u32, slope: f64| AMPLITUDE * steepness(slope) * octave_scale(wavelength(k));
    // Steep land: exactly the one-exponent law (multiplying by 1 changes no bit).
    for slope in [GENTLE_SLOPE, 0.1, 0.6] {
        assert_eq!(gentle_tilt(slope), 1.0);
        for k in 0..MAX_OCTAVES {
            assert_eq!(amplitude(k, slope), plain(k, slope));
        }
    }
    // Flat land: the pivot octave as before, longer ones larger, shorter ones smaller, by
    // 2^(−extra) per octave from the pivot.
    let flat = 0.01;
    let extra = GENTLE_EXTRA_HURST * (1.0 - flat / GENTLE_SLOPE);
    assert!((amplitude(GENTLE_PIVOT, flat) / plain(GENTLE_PIVOT, flat) - 1.0).abs() < 1e-12);
    for k in 0..MAX_OCTAVES {
        let ratio = amplitude(k, flat) / plain(k, flat);
        let expected = 2f64.powf(-extra * (f64::from(k) - f64::from(GENTLE_PIVOT)));
        assert!((ratio / expected - 1.0).abs() < 1e-9, "octave {k}: {ratio} against {expected}");
    }
    // No jump in the amplitudes where the extra fades out: the step across GENTLE_SLOPE
    // shrinks with the distance either side (a jump would not).
    let near = |d: f64| amplitude(6, GENTLE_SLOPE + d) / plain(6, GENTLE_SLOPE + d);
    let step = |d: f64| (near(-d) - near(d)).abs();
    for d in [1e-6, 1e-9, 1e-12] {
        assert!(step(d) < 100.0 * d, "a step of {} at ± {d}", step(d));
    }
    // And the filter carves with them: one octave alone is its amplitude times the same
    // gully noise (the downhill direction is the same), so the heights scale as they do.
    let f = ErosionFilter::new(9);
    let k = GENTLE_PIVOT + 1;
    for i in 0..50 {
        let (x, z) = (f64::from(i) * 37.0, f64::from(i) * -41.0);
        let (low, high) =
            (f.apply(x, z, flat, (flat, 0.0), k..k + 1).height, f.apply(x, z, 0.1, (0.1, 0.0), k..k + 1).height);
        if high.abs() > 1e-6 {
            assert!((low / high / (amplitude(k, flat) / amplitude(k, 0.1)) - 1.0).abs() < 1e-9, "{low} {high}");
        }
    }
    assert!(amplitude(k, flat) > MIN_AMPLITUDE_M, "the octave is carved at all");
}
