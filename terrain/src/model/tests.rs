use std::sync::Arc;

use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::{Device, Tensor, TensorData};

use super::stage::LearnedStage;
use super::*;
use crate::infinite::{Engine, EngineConfig, Source, WindowFn, WindowIndex, Windowed};
use crate::tile::{Rect, Tile};

fn device() -> Device {
    Device::flex()
}

fn randn<const D: usize>(shape: [usize; D], seed: u64) -> Tensor<D> {
    let n = shape.iter().product();
    Tensor::from_data(TensorData::new(HostRng::keyed(seed, 1, 2, 3).normals(n), shape), &device())
}

fn values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().try_into_vec().expect("f32 tensor")
}

fn std_of<const D: usize>(t: Tensor<D>) -> f64 {
    let v = values(t);
    let mean = v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    (v.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
}

fn rms_of<const D: usize>(t: Tensor<D>) -> f64 {
    let v = values(t);
    (v.iter().map(|&x| (x as f64).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
}

#[test]
fn unet_output_has_the_shape_of_its_input() {
    let net = UNet::new(&UNetConfig::tiny(), 1, &device());
    let x = randn([3, 1, 32, 32], 1);
    let cond = randn([3, 1, 32, 32], 2);
    let sigma = Tensor::<1>::from_data(TensorData::new(vec![0.1f32, 1.0, 10.0], [3]), &device());
    let out = net.denoise(x, sigma, Some(cond), Some(Tensor::zeros([3, 2], &device())));
    assert_eq!(out.dims(), [3, 1, 32, 32]);
    assert!(values(out).iter().all(|v| v.is_finite()));
    assert!(net.parameters() > 1000);
}

#[test]
fn the_core_network_is_sized_for_this_cpu() {
    let net = UNet::new(&UNetConfig::core(), 0, &device());
    let params = net.parameters();
    let macs = net.macs_per_pixel();
    assert!((200_000..1_500_000).contains(&params), "{params} parameters");
    assert!((100_000.0..600_000.0).contains(&macs), "{macs} MACs per pixel");
}

#[test]
fn magnitude_preserving_layers_keep_unit_variance() {
    let dev = device();
    let mut rng = HostRng::keyed(5, 0, 0, 0);
    let x = randn([4, 32, 24, 24], 7);
    // 1×1 conv: exactly variance-preserving in expectation.
    let conv1 = MpConv::new(32, 48, 1, &mut rng, &dev);
    let y = std_of(conv1.forward(x.clone()));
    assert!((y - 1.0).abs() < 0.1, "1×1 MP conv std {y}");
    // 3×3 conv: zero padding loses a little at the borders only.
    let conv3 = MpConv::new(32, 32, 3, &mut rng, &dev);
    let y = std_of(conv3.forward(x.clone()));
    assert!((y - 1.0).abs() < 0.12, "3×3 MP conv std {y}");
    let lin = MpLinear::new(64, 40, &mut rng, &dev);
    let y = std_of(lin.forward(randn([256, 64], 8)));
    assert!((y - 1.0).abs() < 0.1, "MP linear std {y}");
    let y = rms_of(mp_silu(x.clone()));
    assert!((y - 1.0).abs() < 0.05, "MP SiLU rms {y}");
    let y = std_of(mp_sum(x.clone(), randn([4, 32, 24, 24], 9), 0.3));
    assert!((y - 1.0).abs() < 0.05, "MP sum std {y}");
    let y = std_of(mp_cat(x.clone(), randn([4, 8, 24, 24], 10), 0.5));
    assert!((y - 1.0).abs() < 0.05, "MP cat std {y}");
    let y = rms_of(pixel_norm(x.mul_scalar(7.0)));
    assert!((y - 1.0).abs() < 0.01, "pixel norm rms {y}");
}

#[test]
fn forced_normalisation_resets_rows_to_unit_rms() {
    let mut rng = HostRng::keyed(3, 0, 0, 0);
    let conv = MpConv::new(4, 6, 3, &mut rng, &device());
    let grown = MpConv { weight: conv.weight.clone().map(|w| w.mul_scalar(5.0)) };
    let fixed = force_normalize(grown);
    let w = values(fixed.weight.val());
    for row in w.chunks(4 * 9) {
        let rms = (row.iter().map(|v| v * v).sum::<f32>() / row.len() as f32).sqrt();
        assert!((rms - 1.0).abs() < 1e-3, "row rms {rms}");
    }
    assert_eq!(fixed.weight.id, conv.weight.id, "forced normalisation keeps the parameter's identity");
}

#[test]
fn an_untrained_denoiser_is_its_skip_connection() {
    // out_gain starts at 0, so D(x; σ) = c_skip·x exactly.
    let net = UNet::new(&UNetConfig::tiny(), 2, &device());
    let x = randn([2, 1, 16, 16], 3);
    let sigma = 2.0f32;
    let out = net.denoise(
        x.clone(),
        Tensor::from_data(TensorData::new(vec![sigma; 2], [2]), &device()),
        Some(randn([2, 1, 16, 16], 4)),
        None,
    );
    let c_skip = 0.25 / (sigma * sigma + 0.25);
    for (o, i) in values(out).iter().zip(values(x)) {
        assert!((o - c_skip * i).abs() < 1e-6);
    }
}

fn fixed_inputs(b: usize) -> (Vec<Tensor<4>>, Tensor<4>, Tensor<2>) {
    let noise = (0..3).map(|k| randn([b, 1, 16, 16], 20 + k)).collect();
    (noise, randn([b, 1, 16, 16], 30), Tensor::zeros([b, 2], &device()))
}

/// A tiny network with non-trivial output (the default has out_gain = 0).
fn perturbed_tiny(seed: u64) -> UNet {
    perturbed_tiny_on(seed, &device())
}

fn perturbed_tiny_on(seed: u64, device: &Device) -> UNet {
    let mut net = UNet::new(&UNetConfig::tiny(), seed, device);
    net.out_gain = net.out_gain.map(|g| g.add_scalar(0.7));
    for b in net.enc.iter_mut().chain(net.dec.iter_mut()) {
        b.emb_gain = b.emb_gain.clone().map(|g| g.add_scalar(0.3));
    }
    net
}

#[test]
fn the_cpu_inference_convolutions_match_burns_own() {
    // On a plain flex device the network convolves with `cpu_conv` (SiLU and modulation
    // fused); on an autodiff device it uses burn's kernels. Same weights, same inputs: the
    // two must agree to float rounding, or inference would not be what training trained.
    let autodiff = device().autodiff();
    let fast = perturbed_tiny(5);
    let reference = perturbed_tiny_on(5, &autodiff);
    let to = |t: &Tensor<4>| Tensor::<4>::from_data(t.to_data(), &autodiff);
    let x = randn([2, 1, 16, 16], 40);
    let cond = randn([2, 1, 16, 16], 41);
    let vector = Tensor::<2>::from_data(TensorData::new(vec![0.8f32, 1.0, -0.5, 1.0], [2, 2]), &device());
    let sigma = Tensor::<1>::from_data(TensorData::new(vec![0.7f32, 3.0], [2]), &device());
    let a = values(fast.denoise(x.clone(), sigma.clone(), Some(cond.clone()), Some(vector.clone())));
    let b = values(reference.denoise(
        to(&x),
        Tensor::from_data(sigma.to_data(), &autodiff),
        Some(to(&cond)),
        Some(Tensor::from_data(vector.to_data(), &autodiff)),
    ));
    let scale = a.iter().map(|v| v.abs()).fold(0.0f32, f32::max);
    let worst = a.iter().zip(&b).map(|(p, q)| (p - q).abs()).fold(0.0f32, f32::max);
    assert!(scale > 0.1, "the network's output is not trivial");
    assert!(worst < 1e-4 * scale.max(1.0), "fast and burn convolutions differ by {worst}");
}

#[test]
fn the_sampler_is_deterministic_for_fixed_noise() {
    let net = perturbed_tiny(4);
    let (noise, cond, vector) = fixed_inputs(2);
    for kind in [SamplerKind::Euler, SamplerKind::Renoise, SamplerKind::DpmPp2m] {
        let sampler = Sampler::karras(kind, 3, 0.05, 40.0, 7.0);
        let a = values(sampler.sample(&net, &noise, Some(cond.clone()), Some(vector.clone())));
        let b = values(sampler.sample(&net, &noise, Some(cond.clone()), Some(vector.clone())));
        assert_eq!(a, b, "{kind:?}");
        assert!(a.iter().all(|v| v.is_finite()));
    }
    let s = Sampler::karras(SamplerKind::Euler, 4, 0.002, 80.0, 7.0);
    assert_eq!(s.sigmas.len(), 4);
    assert!((s.sigmas[0] - 80.0).abs() < 1e-3 && (s.sigmas[3] - 0.002).abs() < 1e-5);
    assert!(s.validate().is_ok());
}

/// With the untrained network (out_gain = 0) the denoiser is D(x; σ) = x·σd²/(σ²+σd²), whose
/// probability-flow ODE dx/dσ = (x − D)/σ has the exact solution x(σ) ∝ √(σ² + σd²). The
/// second-order sampler must land much closer to it than Euler with the same steps.
#[test]
fn dpm_solver_is_more_accurate_than_euler_at_equal_steps() {
    let net = UNet::new(&UNetConfig::tiny(), 3, &device());
    let sd = net.config.sigma_data as f64;
    let noise = vec![Tensor::<4>::ones([1, 1, 16, 16], &device())];
    let (cond, vector) = (randn([1, 1, 16, 16], 31), Tensor::<2>::zeros([1, 2], &device()));
    let error = |kind| {
        let s = Sampler::karras(kind, 4, 0.02, 10.0, 7.0);
        let (first, last) = (s.sigmas[0] as f64, *s.sigmas.last().unwrap() as f64);
        // Exact ODE value at the last level, then the final denoising step.
        let exact =
            first * ((last * last + sd * sd) / (first * first + sd * sd)).sqrt() * sd * sd / (last * last + sd * sd);
        let got = values(s.sample(&net, &noise, Some(cond.clone()), Some(vector.clone())));
        got.iter().map(|&v| (v as f64 - exact).abs() / exact).fold(0.0, f64::max)
    };
    let (euler, dpm) = (error(SamplerKind::Euler), error(SamplerKind::DpmPp2m));
    assert!(dpm < euler / 3.0, "relative error: DPM-Solver++(2M) {dpm:.4}, Euler {euler:.4}");
}

#[test]
fn autoguidance_interpolates_from_the_guide_to_the_model_and_beyond() {
    let (net, weak) = (perturbed_tiny(4), perturbed_tiny(8));
    let (noise, cond, vector) = fixed_inputs(2);
    let sampler = Sampler::karras(SamplerKind::DpmPp2m, 3, 0.05, 10.0, 7.0);
    let run = |weight: f32, steps: usize| {
        let guide = Guide { net: &weak, weight, steps };
        values(sampler.sample_guided(&net, Some(&guide), &noise, Some(cond.clone()), Some(vector.clone())))
    };
    let plain = values(sampler.sample(&net, &noise, Some(cond.clone()), Some(vector.clone())));
    let weak_alone = values(sampler.sample(&weak, &noise, Some(cond.clone()), Some(vector.clone())));
    // w = 0 is the guide exactly; w = 1 the model (to rounding: D_g + (D − D_g)).
    assert_eq!(run(0.0, 3), weak_alone);
    let gap = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(p, q)| (p - q).abs()).fold(0.0f32, f32::max);
    assert!(gap(&run(1.0, 3), &plain) < 1e-5, "w = 1 moved the sample by {}", gap(&run(1.0, 3), &plain));
    // w = 2 extrapolates past the model, away from the guide; guiding fewer steps moves less.
    let (two, two_first) = (run(2.0, 3), run(2.0, 1));
    let spread = gap(&plain, &weak_alone);
    assert!(spread > 1e-3, "the two networks differ");
    assert!(gap(&two, &plain) > 0.1 * spread && gap(&two_first, &plain) > 0.0);
    assert!(gap(&two_first, &plain) < gap(&two, &plain));
}

#[test]
fn a_guided_model_loads_its_guide_and_refuses_one_that_sees_other_inputs() {
    let dir = tempdir("guided");
    let (net, weak) = (perturbed_tiny(6), UNet::new(&UNetConfig::tiny().halved(), 7, &device()));
    save_model(&dir.join("guide"), &weak, manifest_for(&weak), Precision::F32).expect("save guide");
    let mut manifest = manifest_for(&net);
    manifest.guidance = Some(Guidance { guide: "guide/test.json".into(), weight: 2.0, steps: 2 });
    save_model(&dir, &net, manifest, Precision::F32).expect("save model");
    let loaded = load_model(&dir, "test", &device()).expect("load with guide");
    assert_eq!(loaded.guide.as_ref().map(|g| g.config.channels.clone()), Some(vec![4, 8]));

    // A guide trained on other data has another normalisation: its inputs would mean something else.
    let guide_json = dir.join("guide").join("test.json");
    let text = std::fs::read_to_string(&guide_json).expect("read guide manifest");
    std::fs::write(&guide_json, text.replace("\"cond_mean\": 10.0", "\"cond_mean\": 11.0")).expect("write");
    let msg = load_model(&dir, "test", &device()).expect_err("mismatched guide").to_string();
    assert!(msg.contains("guide/test.json") && msg.contains("normalisation"), "{msg}");

    std::fs::remove_file(dir.join("guide").join("test.safetensors")).expect("remove");
    let msg = load_model(&dir, "test", &device()).expect_err("guide weights gone").to_string();
    assert!(msg.contains("guide/test.safetensors") && msg.contains("missing"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

fn manifest_for(net: &UNet) -> ModelManifest {
    let mut manifest =
        ModelManifest::new("test", net.config.clone(), Sampler::karras(SamplerKind::Renoise, 2, 0.3, 40.0, 7.0));
    manifest.metres_per_pixel = 1000.0;
    manifest.normalisation =
        Normalisation { target_scale: 4.0, cond_mean: 10.0, cond_scale: 20.0, relief_mean: 0.0, relief_std: 1.0 };
    manifest
}

#[test]
fn save_then_load_gives_bit_identical_outputs() {
    let dir = tempdir("roundtrip");
    let net = perturbed_tiny(6);
    let written = save_model(&dir, &net, manifest_for(&net), Precision::F32).expect("save");
    assert_eq!(written.parameters, net.parameters());
    let loaded = load_model(&dir, "test", &device()).expect("load");
    assert_eq!(loaded.manifest, written);
    let (noise, cond, vector) = fixed_inputs(2);
    let sampler = &written.sampler;
    let a = values(sampler.sample(&net, &noise, Some(cond.clone()), Some(vector.clone())));
    let b = values(sampler.sample(&loaded.net, &noise, Some(cond), Some(vector)));
    assert_eq!(a, b);

    // f16 halves the file and stays close.
    let half_dir = dir.join("half");
    let half = save_model(&half_dir, &net, manifest_for(&net), Precision::F16).expect("save f16");
    assert!(half.weights_bytes * 10 < written.weights_bytes * 6, "{} vs {}", half.weights_bytes, written.weights_bytes);
    let loaded = load_model(&half_dir, "test", &device()).expect("load f16");
    let (noise, cond, vector) = fixed_inputs(2);
    let c = values(sampler.sample(&loaded.net, &noise, Some(cond), Some(vector)));
    let worst = a.iter().zip(&c).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
    assert!(worst < 0.05, "f16 weights moved outputs by {worst}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn missing_or_corrupt_weights_name_the_file_and_the_command() {
    let dir = tempdir("corrupt");
    let err = load_model(&dir, "core", &device()).expect_err("nothing there");
    let msg = err.to_string();
    assert!(msg.contains("core.json") && msg.contains("infiniterra train core"), "{msg}");

    let net = UNet::new(&UNetConfig::tiny(), 1, &device());
    save_model(&dir, &net, manifest_for(&net), Precision::F32).expect("save");
    let weights = dir.join("test.safetensors");
    let mut bytes = std::fs::read(&weights).expect("read back");
    let last = bytes.len() - 1;
    bytes[last] ^= 0x5a;
    std::fs::write(&weights, &bytes).expect("write");
    let msg = load_model(&dir, "test", &device()).expect_err("flipped byte").to_string();
    assert!(
        msg.contains("test.safetensors") && msg.contains("SHA-256") && msg.contains("infiniterra train test"),
        "{msg}"
    );

    std::fs::remove_file(&weights).expect("remove");
    let msg = load_model(&dir, "test", &device()).expect_err("no weights").to_string();
    assert!(msg.contains("test.safetensors") && msg.contains("missing"), "{msg}");

    std::fs::write(dir.join("test.json"), "{ not json").expect("write");
    let msg = load_model(&dir, "test", &device()).expect_err("bad manifest").to_string();
    assert!(msg.contains("test.json") && msg.contains("not a model manifest"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_few_adam_steps_reduce_the_loss_on_a_fixed_batch() {
    let dev = device().autodiff();
    let mut net = UNet::new(&UNetConfig::tiny(), 9, &dev);
    let mut optim = AdamConfig::new().with_beta_2(0.99).init();
    let mut rng = HostRng::keyed(1, 0, 0, 0);
    let b = 4;
    let clean: Vec<f32> = (0..b * 256).map(|i| 0.5 * ((i % 16) as f32 * 0.7).sin()).collect();
    let noise = rng.normals(b * 256);
    let sigma = vec![0.3f32, 0.6, 1.0, 2.0];
    let make = |v: &Vec<f32>| Tensor::<4>::from_data(TensorData::new(v.clone(), [b, 1, 16, 16]), &dev);
    let cond = Tensor::<4>::zeros([b, 1, 16, 16], &dev);
    let mut losses = Vec::new();
    for _ in 0..20 {
        let loss = edm_loss(&net, make(&clean), make(&noise), &sigma, Some(cond.clone()), None);
        losses.push(values(loss.clone().inner())[0]);
        let grads = GradientsParams::from_grads(loss.backward(), &net);
        net = force_normalize(optim.step(2e-2, net, grads));
    }
    assert!(losses[19] < 0.8 * losses[0], "losses {losses:?}");
}

fn tempdir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("infiniterra-model-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// A smooth, deterministic coarse field (metres) standing in for the coarse stage.
struct Hills;

impl Source for Hills {
    fn channels(&self) -> usize {
        1
    }
    fn query(&self, rect: Rect) -> Tile {
        let mut data = Vec::with_capacity(rect.area());
        for y in rect.y0..rect.y1() {
            for x in rect.x0..rect.x1() {
                data.push(800.0 * ((y as f32) * 0.3).sin() * ((x as f32) * 0.2).cos() + 300.0);
            }
        }
        Tile::from_data(1, rect, data)
    }
}

fn tiny_core(batch: usize) -> LearnedStage {
    tiny_core_with(batch, None)
}

fn tiny_core_with(batch: usize, equaliser: Option<SpectralEqualiser>) -> LearnedStage {
    tiny_core_full(batch, equaliser, None)
}

fn tiny_core_full(
    batch: usize,
    equaliser: Option<SpectralEqualiser>,
    infill: Option<DepressionInfill>,
) -> LearnedStage {
    let net = perturbed_tiny(11);
    let mut manifest = manifest_for(&net);
    manifest.window = 32;
    manifest.normalisation =
        Normalisation { target_scale: 4.0, cond_mean: 10.0, cond_scale: 20.0, relief_mean: 0.0, relief_std: 1.0 };
    manifest.spectral_equaliser = equaliser;
    manifest.depression_infill = infill;
    LearnedStage::new(LoadedModel { net, manifest, guide: None }, device(), Arc::new(Hills), 42, batch)
}

/// A fine field (metres) and its coarse grid as the pipeline provides it: box means over
/// 8×8 fine cells, in signed sqrt (as training averages), returned in metres.
fn fine_metres(y: i64, x: i64) -> f32 {
    let (y, x) = (y as f32, x as f32);
    900.0 * (y * 0.021).sin() * (x * 0.017).cos() + 120.0 * (x * 0.31 + y * 0.13).sin() + 200.0
}

struct BoxMeans;

impl Source for BoxMeans {
    fn channels(&self) -> usize {
        1
    }

    fn query(&self, rect: Rect) -> Tile {
        let data = (rect.y0..rect.y1())
            .flat_map(|cy| (rect.x0..rect.x1()).map(move |cx| (cy, cx)))
            .map(|(cy, cx)| {
                let mut sum = 0.0;
                for y in cy * 8..cy * 8 + 8 {
                    for x in cx * 8..cx * 8 + 8 {
                        sum += crate::encoding::signed_sqrt(fine_metres(y, x));
                    }
                }
                crate::encoding::signed_square(sum / 64.0)
            })
            .collect();
        Tile::from_data(1, rect, data)
    }
}

#[test]
fn a_window_s_context_is_the_low_band_training_computes() {
    use crate::encoding::{lowpass, signed_sqrt, upsample_low};
    let net = perturbed_tiny(11);
    let mut manifest = manifest_for(&net);
    manifest.window = 32;
    let stage = LearnedStage::new(LoadedModel { net, manifest, guide: None }, device(), Arc::new(BoxMeans), 1, 1);
    // Training: a 160² tile (origin on the 8-cell grid) encoded whole; the window sits in its
    // interior, away from the tile's clamped edges.
    let (t0, n) = ((-64i64, 40i64), 160usize);
    let h: Vec<f32> =
        (0..n as i64).flat_map(|y| (0..n as i64).map(move |x| signed_sqrt(fine_metres(t0.0 + y, t0.1 + x)))).collect();
    let low = upsample_low(&lowpass(&h, n, n), n, n);
    let window = Rect::new(t0.0 + 64, t0.1 + 48, 32, 32);
    let (_, got, _) = stage.context(window);
    let mut worst = 0.0f32;
    for y in 0..32 {
        for x in 0..32 {
            let want = low[(64 + y) * n + 48 + x];
            worst = worst.max((got[y * 32 + x] - want).abs());
        }
    }
    assert!(worst < 1e-3, "context differs from training's low band by {worst} (signed-sqrt metres)");
}

#[test]
fn the_relief_hint_steers_each_window_from_its_own_context() {
    use crate::model::hint::FEATURE_NAMES;
    let plain = tiny_core(2);
    let region = Rect::new(-40, 25, 48, 40);
    let engine = Engine::new(EngineConfig { cache_bytes: 64 << 20, threads: 2 });
    let without = Windowed::new(&engine, tiny_core(2)).query(region);

    let net = perturbed_tiny(11);
    let mut manifest = manifest_for(&net);
    manifest.window = 32;
    manifest.normalisation =
        Normalisation { target_scale: 4.0, cond_mean: 10.0, cond_scale: 20.0, relief_mean: 0.0, relief_std: 1.0 };
    manifest.relief_hint = Some(ReliefHint {
        features: FEATURE_NAMES.iter().map(|s| s.to_string()).collect(),
        coefficients: vec![0.5, 0.1, 0.8, 0.3, 0.2, -0.1, 0.3, 0.4],
        r2: 0.9,
        offset: 0.2,
        response: Vec::new(),
    });
    let hinted = LearnedStage::new(
        LoadedModel { net, manifest: manifest.clone(), guide: None },
        device(),
        Arc::new(Hills),
        42,
        2,
    );
    // Each window's vector is the hint's prediction from that window's own low band.
    let windows = [Rect::new(0, 0, 32, 32), Rect::new(-80, 48, 32, 32)];
    let lows: Vec<Vec<f32>> = windows.iter().map(|&r| hinted.context(r).1).collect();
    let v = hinted.conditioning_vector(&lows).expect("the tiny net takes a vector");
    let hint = manifest.relief_hint.as_ref().expect("set above");
    for (row, low) in v.chunks(2).zip(&lows) {
        assert_eq!(row, [hint.predict(low, 32), 1.0]);
    }
    assert_ne!(v[0], v[2], "two different contexts gave the same relief hint");
    assert_eq!(plain.conditioning_vector(&lows), Some(vec![0.0; 4]), "no hint: the dropped (zero) vector");
    // And it reaches the network: the terrain differs, still finite and seed-consistent.
    let engine = Engine::new(EngineConfig { cache_bytes: 64 << 20, threads: 1 });
    let with = Windowed::new(&engine, hinted).query(region);
    assert!(with.data.iter().all(|x| x.is_finite()));
    assert_ne!(with, without);

    // A manifest whose hint this build cannot compute is refused, naming the entry.
    let dir = tempdir("hint");
    let net = perturbed_tiny(11);
    save_model(&dir, &net, manifest, Precision::F32).expect("save");
    let path = dir.join("test.json");
    let text = std::fs::read_to_string(&path).expect("read").replace("ln_std_low", "ln_std_of_something_else");
    std::fs::write(&path, text).expect("write");
    let msg = load_model(&dir, "test", &device()).expect_err("foreign hint").to_string();
    assert!(msg.contains("test.json") && msg.contains("relief_hint.features"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_core_stage_is_seed_consistent_through_the_engine() {
    let region = Rect::new(-40, 25, 48, 40);
    let engine = Engine::new(EngineConfig { cache_bytes: 64 << 20, threads: 2 });
    let whole = Windowed::new(&engine, tiny_core(4)).query(region);
    assert!(whole.data.iter().all(|v| v.is_finite()));
    // Another engine, other batch size, one thread, piecewise queries: same values.
    let engine = Engine::new(EngineConfig { cache_bytes: 1 << 20, threads: 1 });
    let tensor = Windowed::new(&engine, tiny_core(3));
    let part = tensor.query(Rect::new(-20, 40, 16, 16));
    assert_eq!(whole.crop(part.rect), part);
    assert_eq!(tensor.query(region), whole);
}

/// Speed of the core network on this machine: network evaluations of 64×64 windows per
/// second by batch size, and the core stage through the engine (2 threads) on a 256² region.
#[test]
#[ignore = "benchmark: cargo test -p infiniterra-terrain --features learned bench_core -- --ignored --nocapture"]
fn bench_core_windows_per_second() {
    let net = UNet::new(&UNetConfig::core(), 0, &device());
    let flop = 2.0 * net.macs_per_pixel() * 64.0 * 64.0;
    for batch in [1usize, 4, 8, 16] {
        let x = randn([batch, 1, 64, 64], 1);
        let cond = randn([batch, 1, 64, 64], 2);
        let sigma = Tensor::<1>::from_data(TensorData::new(vec![1.0f32; batch], [batch]), &device());
        let run = || values(net.denoise(x.clone(), sigma.clone(), Some(cond.clone()), None));
        run();
        let reps = (32 / batch).max(2);
        let t = std::time::Instant::now();
        for _ in 0..reps {
            run();
        }
        let secs = t.elapsed().as_secs_f64();
        let wps = (reps * batch) as f64 / secs;
        println!("batch {batch:2}: {wps:6.1} windows/s per network evaluation, {:.1} GFLOP/s", wps * flop / 1e9);
    }
    for steps in [1usize, 2, 4] {
        let mut manifest = manifest_for(&net);
        manifest.sampler = Sampler::karras(SamplerKind::Euler, steps, 0.05, 80.0, 7.0);
        manifest.normalisation =
            Normalisation { target_scale: 4.0, cond_mean: 10.0, cond_scale: 20.0, relief_mean: 0.0, relief_std: 1.0 };
        let model = LoadedModel { net: UNet::new(&UNetConfig::core(), 0, &device()), manifest, guide: None };
        let engine = Engine::new(EngineConfig { cache_bytes: 256 << 20, threads: 2 });
        let tensor = Windowed::new(&engine, LearnedStage::new(model, device(), Arc::new(Hills), 1, 8));
        let t = std::time::Instant::now();
        let _ = tensor.query(Rect::new(0, 0, 256, 256));
        let secs = t.elapsed().as_secs_f64();
        let windows = tensor.evaluations();
        println!(
            "core stage, {steps}-step sampler, 256² region: {windows} windows in {secs:.2} s = {:.1} windows/s, {:.0} px/s",
            windows as f64 / secs,
            65536.0 / secs
        );
    }
}

/// One core window on wgpu (Mesa's software Vulkan in CI) and on the CPU backend: same
/// weights, same noise, outputs within float tolerance.
#[cfg(feature = "wgpu")]
#[test]
fn one_core_window_on_wgpu_matches_the_cpu_backend() {
    let dir = tempdir("wgpu");
    let net = perturbed_tiny(11);
    let mut manifest = manifest_for(&net);
    manifest.window = 32;
    save_model(&dir, &net, manifest, Precision::F32).expect("save");
    let run = |backend: ComputeBackend| {
        let device = backend.device().expect("backend built in");
        let model = load_model(&dir, "test", &device).expect("load");
        let engine = Engine::new(EngineConfig { cache_bytes: 1 << 20, threads: 1 });
        // One window: a 16×16 query inside the first window's unshared core.
        Windowed::new(&engine, LearnedStage::new(model, device, Arc::new(Hills), 42, 1)).query(Rect::new(8, 8, 16, 16))
    };
    let (cpu, gpu) = (run(ComputeBackend::Cpu), run(ComputeBackend::Wgpu));
    assert!(gpu.data.iter().all(|v| v.is_finite()));
    let scale = cpu.data.iter().fold(1.0f32, |m, v| m.max(v.abs()));
    let worst = cpu.data.iter().zip(&gpu.data).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    eprintln!("wgpu vs cpu: worst difference {worst} m (values up to {scale} m)");
    assert!(worst <= 1e-3 * scale, "wgpu differs from the CPU by {worst} m (values up to {scale} m)");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_sample_denoises_to_the_same_bits_whatever_batch_it_is_in() {
    // The engine batches windows by what a query finds missing, so a window's result must not
    // depend on its batch (burn's matmul picks kernels by shape; it did, by a rounding step).
    use burn::tensor::TensorData;
    let dev = Device::flex();
    // The shipped core's weights: fresh random ones (even saved and loaded back) did not show
    // the difference; these did.
    let models = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let net = load_model(&models, "core", &dev).expect("the shipped core loads").net;
    let mut rng = HostRng::keyed(1, 2, 3, 4);
    let (b, s) = (3usize, 32usize);
    let (x, c) = (rng.normals(b * s * s), rng.normals(b * s * s));
    let v: Vec<f32> = vec![0.3, 1.0, -0.7, 1.0, 1.2, 1.0];
    let run = |i0: usize, n: usize| {
        let part = |v: &[f32]| {
            Tensor::<4>::from_data(TensorData::new(v[i0 * s * s..(i0 + n) * s * s].to_vec(), [n, 1, s, s]), &dev)
        };
        let vt = Tensor::<2>::from_data(TensorData::new(v[i0 * 2..(i0 + n) * 2].to_vec(), [n, 2]), &dev);
        let sigma = Tensor::<1>::from_data(TensorData::new(vec![2.0f32; n], [n]), &dev);
        net.denoise(part(&x), sigma, Some(part(&c)), Some(vt)).into_data().try_into_vec::<f32>().expect("f32")
    };
    let all = run(0, 3);
    for i in 0..3 {
        assert!(
            run(i, 1)[..] == all[i * s * s..(i + 1) * s * s],
            "sample {i} alone differs from sample {i} in a batch of 3"
        );
    }
}

#[test]
fn the_spectral_equaliser_filters_each_window_before_the_blend_and_is_checked_on_load() {
    use super::equaliser::EqualiserKernel;
    let eq = SpectralEqualiser { radius: 6, gains: vec![[32.0, 1.0], [16.0, 1.4], [4.0, 0.6]] };
    let windows = [WindowIndex { iy: -1, ix: 2 }, WindowIndex { iy: 0, ix: 0 }];
    let plain = tiny_core(2).eval(&windows);
    let filtered = tiny_core_with(2, Some(eq.clone())).eval(&windows);
    let kernel = EqualiserKernel::new(&eq);
    for (p, f) in plain.iter().zip(&filtered) {
        assert_eq!(f.rect, p.rect);
        assert!(f.data == kernel.apply(&p.data, 32), "window {:?} is not its network output, filtered", f.rect);
        assert_ne!(f.data, p.data);
    }
    // Through the engine it stays a pure function of the region: other batch, other thread
    // count, piecewise queries.
    let region = Rect::new(-40, 25, 48, 40);
    let whole = Windowed::new(
        &Engine::new(EngineConfig { cache_bytes: 64 << 20, threads: 2 }),
        tiny_core_with(4, Some(eq.clone())),
    )
    .query(region);
    let tensor = Windowed::new(
        &Engine::new(EngineConfig { cache_bytes: 1 << 20, threads: 1 }),
        tiny_core_with(3, Some(eq.clone())),
    );
    let part = tensor.query(Rect::new(-20, 40, 16, 16));
    assert_eq!(whole.crop(part.rect), part);

    // A radius the 32-pixel windows cannot mirror is refused on load, naming the entry.
    let dir = tempdir("equaliser");
    let net = perturbed_tiny(11);
    let mut manifest = manifest_for(&net);
    manifest.window = 32;
    manifest.spectral_equaliser = Some(SpectralEqualiser { radius: 40, ..eq });
    save_model(&dir, &net, manifest, Precision::F32).expect("save");
    let msg = load_model(&dir, "test", &device()).expect_err("radius past the window").to_string();
    assert!(msg.contains("test.json") && msg.contains("spectral_equaliser.radius"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_depression_infill_follows_the_equaliser_in_each_window_and_is_checked_on_load() {
    use super::equaliser::EqualiserKernel;
    let eq = SpectralEqualiser { radius: 6, gains: vec![[32.0, 1.0], [16.0, 1.4], [4.0, 0.6]] };
    let infill = DepressionInfill { depth_scale_m: 3.0 };
    let windows = [WindowIndex { iy: -1, ix: 2 }, WindowIndex { iy: 0, ix: 0 }, WindowIndex { iy: 1, ix: -1 }];
    let plain = tiny_core(3).eval(&windows);
    let done = tiny_core_full(3, Some(eq.clone()), Some(infill.clone())).eval(&windows);
    let kernel = EqualiserKernel::new(&eq);
    let mut changed = 0;
    for (p, d) in plain.iter().zip(&done) {
        assert_eq!(d.rect, p.rect);
        let expected = infill.apply(&kernel.apply(&p.data, 32), 32);
        assert!(d.data == expected, "window {:?} is not its network output, equalised, then infilled", d.rect);
        changed += usize::from(expected != kernel.apply(&p.data, 32));
    }
    assert!(changed > 0, "no window had a closed basin to fill: the test shows nothing");
    // Through the engine it stays a pure function of the region.
    let region = Rect::new(-40, 25, 48, 40);
    let whole = Windowed::new(
        &Engine::new(EngineConfig { cache_bytes: 64 << 20, threads: 2 }),
        tiny_core_full(4, Some(eq.clone()), Some(infill.clone())),
    )
    .query(region);
    let part = Windowed::new(
        &Engine::new(EngineConfig { cache_bytes: 1 << 20, threads: 1 }),
        tiny_core_full(3, Some(eq), Some(infill)),
    )
    .query(Rect::new(-20, 40, 16, 16));
    assert_eq!(whole.crop(part.rect), part);

    // A depth scale that is not a positive number is refused on load, naming the entry.
    let dir = tempdir("infill");
    let net = perturbed_tiny(11);
    let mut manifest = manifest_for(&net);
    manifest.window = 32;
    manifest.depression_infill = Some(DepressionInfill { depth_scale_m: -1.0 });
    save_model(&dir, &net, manifest, Precision::F32).expect("save");
    let msg = load_model(&dir, "test", &device()).expect_err("negative depth scale").to_string();
    assert!(msg.contains("test.json") && msg.contains("depression_infill.depth_scale_m"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The tiny core on an unblurred 8× context (the shipped core's), with a context projection
/// or without.
fn tiny_core_projected(batch: usize, projection: Option<ContextProjection>) -> LearnedStage {
    let net = perturbed_tiny(11);
    let mut manifest = manifest_for(&net);
    manifest.window = 32;
    manifest.context = crate::encoding::ContextSpec { factor: 8, blur: false };
    manifest.normalisation =
        Normalisation { target_scale: 4.0, cond_mean: 10.0, cond_scale: 20.0, relief_mean: 0.0, relief_std: 1.0 };
    manifest.context_projection = projection;
    LearnedStage::new(LoadedModel { net, manifest, guide: None }, device(), Arc::new(Hills), 42, batch)
}

#[test]
fn the_context_projection_makes_each_window_average_to_its_context_and_is_checked_on_load() {
    use crate::encoding::box_downsample;
    use crate::encoding::signed_sqrt;
    let projection = ContextProjection { iterations: 6 };
    let windows = [WindowIndex { iy: -1, ix: 2 }, WindowIndex { iy: 0, ix: 0 }, WindowIndex { iy: 1, ix: -1 }];
    let plain = tiny_core_projected(3, None);
    let projected = tiny_core_projected(3, Some(projection.clone()));
    let (before, after) = (plain.eval(&windows), projected.eval(&windows));
    // Cell means of the output (signed sqrt, as training's context is made) against the
    // window's context cells.
    let miss = |t: &Tile| {
        let h: Vec<f32> = t.data.iter().map(|&m| signed_sqrt(m)).collect();
        let cells = plain.context(t.rect).2;
        box_downsample(&h, 32, 32, 8).iter().zip(&cells).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max)
    };
    for (b, a) in before.iter().zip(&after) {
        assert_eq!(a.rect, b.rect);
        let (was, is) = (miss(b), miss(a));
        assert!(
            was > 0.5,
            "window {:?}: the network already matched its context ({was}): the test shows nothing",
            a.rect
        );
        assert!(is < 0.02 * was, "window {:?}: cell means miss the context by {is} (network alone: {was})", a.rect);
    }
    // Through the engine it stays a pure function of the region.
    let region = Rect::new(-40, 25, 48, 40);
    let whole = Windowed::new(
        &Engine::new(EngineConfig { cache_bytes: 64 << 20, threads: 2 }),
        tiny_core_projected(4, Some(projection.clone())),
    )
    .query(region);
    let part = Windowed::new(
        &Engine::new(EngineConfig { cache_bytes: 1 << 20, threads: 1 }),
        tiny_core_projected(3, Some(projection.clone())),
    )
    .query(Rect::new(-20, 40, 16, 16));
    assert_eq!(whole.crop(part.rect), part);

    // On a blurred context (whose cells are not what the output averages to) it is refused on
    // load, naming the file and the entry.
    let dir = tempdir("projection");
    let net = perturbed_tiny(11);
    let mut manifest = manifest_for(&net);
    manifest.window = 32;
    manifest.context = crate::encoding::ContextSpec { factor: 8, blur: true };
    manifest.context_projection = Some(projection);
    save_model(&dir, &net, manifest, Precision::F32).expect("save");
    let msg = load_model(&dir, "test", &device()).expect_err("blurred context").to_string();
    assert!(msg.contains("test.json") && msg.contains("context_projection"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}
