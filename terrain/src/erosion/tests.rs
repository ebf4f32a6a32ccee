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
        let amp = amplitude(lambda, slope);
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
