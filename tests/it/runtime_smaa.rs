//! SMAA 1x: GPU vs CPU reference on the same inputs, and antialiasing quality against a 16× supersampled
//! ground truth. Textures: rtbake's own bake (`baked/`, through the manifest-checked loader).

use crate::support::*;
use rtbake::runtime::cpu;
use rtbake::runtime::scene::render_shapes;
use rtbake::runtime::smaa::Smaa;

fn gpu_vs_cpu(w: u32, h: u32) {
    let g = gpu();
    let luts = baked_smaa();
    let img = render_shapes(w, h, 1);
    let pass = Smaa::new(&g.device, &g.queue, w, h, &luts).unwrap();
    let out = pass.run(&g.device, &g.queue, &img).unwrap();
    let edges = pass.read_edges(&g.device, &g.queue).unwrap();
    let weights = rtbake::runtime::gpu::read_texture(&g.device, &g.queue, pass.weights()).unwrap();
    let c = cpu::smaa::smaa(&img, w, h, &luts, precision(&g));
    let (fe, me) = within(&edges, &c.edges, 0);
    let (fw, mw) = within(&weights, &c.weights, 1);
    let (fo, mo) = within(&out, &c.output, 1);
    let edge_px = c.edges.chunks(2).filter(|e| e[0] > 0 || e[1] > 0).count();
    eprintln!(
        "{w}x{h}: {edge_px} edge pixels; edges exact {:.5} (max {me}); weights ±1 {:.5} (max {mw}); \
         output ±1 {:.5} (max {mo}); output pixels ±1 {:.5}",
        fe,
        fw,
        fo,
        pixels_within(&out, &c.output, 4, 1)
    );
    assert!(edge_px > 0, "the test scene must have edges");
    let name = format!("smaa_{w}x{h}");
    assert_gpu_matches_cpu(&name, fe >= 0.9999, &format!("edges exact {fe}"), (w, h, 2), &edges, &c.edges);
    assert_gpu_matches_cpu(&name, fo >= 0.999, &format!("output within 1/255 {fo}"), (w, h, 4), &out, &c.output);
    assert!(out != img, "SMAA must change the aliased image");
}

#[test]
fn a_failing_comparison_writes_the_two_images_and_their_difference() {
    let (gpu_img, mut cpu_img) = (vec![10u8; 4 * 6 * 4], vec![10u8; 4 * 6 * 4]);
    cpu_img[0] = 12;
    let caught = std::panic::catch_unwind(|| {
        assert_gpu_matches_cpu("comparison_self_test", false, "one sample", (4, 6, 4), &gpu_img, &cpu_img)
    });
    let message = *caught.unwrap_err().downcast::<String>().unwrap();
    let dir = comparison_dir("comparison_self_test");
    assert!(message.contains(&dir.display().to_string()), "{message}");
    let diff = std::fs::read(dir.join("difference.png")).unwrap();
    let rtbake::io::png::DecodedPng::U8(diff) = rtbake::io::png::decode(&diff, "difference.png").unwrap() else {
        panic!("difference.png is not 8-bit")
    };
    assert_eq!((diff.width, diff.height, diff.channels), (4, 6, 4));
    // |10 − 12| × 16 at the first sample, 0 elsewhere (alpha 255).
    assert_eq!(&diff.data[..8], &[32, 0, 0, 255, 0, 0, 0, 255]);
    for f in ["gpu.png", "cpu.png"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
}

#[test]
fn smaa_gpu_matches_cpu_256() {
    gpu_vs_cpu(256, 256);
}

#[test]
fn smaa_gpu_matches_cpu_odd_size() {
    gpu_vs_cpu(301, 173);
}

#[test]
fn smaa_gpu_matches_cpu_1080p() {
    gpu_vs_cpu(1920, 1080);
}

use crate::support::edge_error_and_psnr as errors;

#[test]
fn smaa_reduces_error_against_supersampled_truth() {
    let (w, h) = (384, 384);
    let g = gpu();
    let aliased = render_shapes(w, h, 1);
    let truth = render_shapes(w, h, 4); // 16 samples per pixel
    let pass = Smaa::new(&g.device, &g.queue, w, h, &baked_smaa()).unwrap();
    let smaa = pass.run(&g.device, &g.queue, &aliased).unwrap();
    // Edge pixels: where the aliased image is visibly wrong.
    let mask: Vec<bool> =
        aliased.chunks(4).zip(truth.chunks(4)).map(|(a, t)| (0..3).any(|k| a[k].abs_diff(t[k]) > 8)).collect();
    let edge_px = mask.iter().filter(|m| **m).count();
    let (mae_aliased, psnr_aliased) = errors(&aliased, &truth, &mask);
    let (mae_smaa, psnr_smaa) = errors(&smaa, &truth, &mask);
    eprintln!(
        "{edge_px} edge pixels: mean abs error aliased {mae_aliased:.2}, SMAA {mae_smaa:.2} (/255); \
         PSNR aliased {psnr_aliased:.2} dB, SMAA {psnr_smaa:.2} dB"
    );
    assert!(edge_px > 1000);
    assert!(mae_smaa < 0.7 * mae_aliased, "SMAA must clearly reduce the edge error: {mae_smaa} vs {mae_aliased}");
    assert!(psnr_smaa > psnr_aliased + 2.0, "PSNR must improve by > 2 dB: {psnr_smaa} vs {psnr_aliased}");
}

/// The S2x/T2x and 4x slices of the area texture: GPU and CPU agree, and the output differs from 1x.
#[test]
fn smaa_subsample_slices_gpu_matches_cpu() {
    use rtbake::runtime::smaa::SubsampleIndices;
    let (w, h) = (192, 160);
    let g = gpu();
    let luts = baked_smaa();
    let img = render_shapes(w, h, 1);
    let one_x = cpu::smaa::smaa(&img, w, h, &luts, precision(&g)).weights;
    for s in SubsampleIndices::SMAA_2X.into_iter().chain(SubsampleIndices::SMAA_4X) {
        let pass = Smaa::with_subsample(&g.device, &g.queue, w, h, &luts, s).unwrap();
        let out = pass.run(&g.device, &g.queue, &img).unwrap();
        let weights = rtbake::runtime::gpu::read_texture(&g.device, &g.queue, pass.weights()).unwrap();
        let c = cpu::smaa::smaa_with_subsample(&img, w, h, &luts, precision(&g), s);
        let (fo, _) = within(&out, &c.output, 1);
        let (fw, _) = within(&weights, &c.weights, 1);
        assert!(fo >= 0.999 && fw >= 0.999, "{s:?}: output {fo}, weights {fw}");
        assert_ne!(c.weights, one_x, "{s:?} must read other slices than 1x");
    }
    assert!(SubsampleIndices([7, 0, 0, 0]).validate().is_err());
}

/// The compute and fragment shapes of the SMAA and MLAA passes (`runtime::aa::three_pass::PassShape`) write the same
/// bytes: edges, blending weights and output, on the shapes scene (odd size: partial workgroups and an odd last
/// edge pair), the moving scene's textured frame (edges almost everywhere), with every edge detector (colour, depth,
/// predicated luma and colour: the other detectors' compute edge passes feeding the compute weights pass) and with a
/// mask (alone and with depth edges); the compute shape records no render pass. The compute shape writes its
/// edges texture in both forms (`EdgeFormat`): the device's (`Rg8Unorm` where the adapter allows it as a storage
/// texture, as lavapipe does) and the portable `Rgba8Unorm`.
#[test]
fn compute_and_fragment_passes_write_the_same_bytes() {
    for portable in [false, true] {
        compute_and_fragment_bytes(portable);
    }
}

fn compute_and_fragment_bytes(portable: bool) {
    use rtbake::runtime::aa::edges::{AaInputs, EdgeDetector, EdgeSettings, Predication};
    use rtbake::runtime::aa::three_pass::{set_portable_edges, EdgeFormat, PassShape, ThreePass};
    use rtbake::runtime::mlaa::{Mlaa, MlaaAreaMap, MlaaOptions};
    use rtbake::runtime::moving_scene::{MovingScene, SceneMotion};
    use rtbake::runtime::scene::render_shapes_depth;
    use rtbake::runtime::smaa::SmaaOptions;
    let g = gpu();
    let (luts, map) = (baked_smaa(), MlaaAreaMap::new(33, baked_mlaa(33)).unwrap());
    let read = |t: &wgpu::Texture| rtbake::runtime::gpu::read_texture(&g.device, &g.queue, t).unwrap();
    let images = |p: &ThreePass, img: &[u8], inputs: &AaInputs| {
        let out = p.run_with(&g.device, &g.queue, img, inputs).unwrap();
        [p.read_edges(&g.device, &g.queue).unwrap(), read(p.weights()), out]
    };
    let detector = |detector, predication| EdgeSettings { detector, predication, ..Default::default() };
    let pred = Some(Predication::SMAA);
    let (w, h) = (301u32, 173u32);
    let mask: Vec<u8> = (0..w * h).map(|i| if (i % w) < w / 2 { 255 } else { 0 }).collect();
    let depth = render_shapes_depth(w, h);
    let moving = MovingScene::new(w, h, SceneMotion::DEFAULT).unwrap().render(1.0, [0.0, 0.0]);
    let shapes = render_shapes(w, h, 1);
    let cases: [(&str, &[u8], EdgeSettings, bool); 8] = [
        ("shapes", &shapes, EdgeSettings::default(), false),
        ("moving scene", &moving, EdgeSettings::default(), false),
        ("colour edges", &shapes, detector(EdgeDetector::Color, None), false),
        ("depth edges", &shapes, detector(EdgeDetector::Depth, None), false),
        ("predicated luma", &shapes, detector(EdgeDetector::Luma, pred), false),
        ("predicated colour", &moving, detector(EdgeDetector::Color, pred), false),
        ("masked", &shapes, EdgeSettings::default(), true),
        ("masked depth edges", &shapes, detector(EdgeDetector::Depth, None), true),
    ];
    for (name, img, edges, masked) in &cases {
        let inputs = AaInputs {
            depth: edges.needs_depth().then_some(depth.as_slice()),
            mask: masked.then_some(mask.as_slice()),
        };
        let (smaa_options, mlaa_options) = (
            SmaaOptions { edges: *edges, masked: *masked, ..Default::default() },
            MlaaOptions { edges: *edges, masked: *masked },
        );
        let smaa = |s| Smaa::with_shape(&g.device, &g.queue, (w, h), &luts, &smaa_options, s).unwrap();
        let mlaa = |s| Mlaa::with_shape(&g.device, &g.queue, (w, h), &map, &mlaa_options, s).unwrap();
        set_portable_edges(portable);
        let (sc, sf) = (smaa(PassShape::Compute), smaa(PassShape::Fragment));
        assert_eq!((sc.shape(), sf.shape()), (PassShape::Compute, PassShape::Fragment));
        let (mc, mf) = (mlaa(PassShape::Compute), mlaa(PassShape::Fragment));
        let format = EdgeFormat::for_device(&g.device);
        set_portable_edges(false);
        assert_eq!(format == EdgeFormat::Rgba8, portable || EdgeFormat::for_device(&g.device) == EdgeFormat::Rgba8);
        for p in [&*sc, &*mc] {
            assert_eq!(p.edges().format(), format.texture_format(), "{name}: the compute shape's edges texture");
        }
        assert_eq!(sf.edges().format(), wgpu::TextureFormat::Rg8Unorm);
        let fragment_passes = 3 + !edges.is_plain_luma() as u32 + *masked as u32;
        for (pass, c, f) in [("SMAA", &*sc, &*sf), ("MLAA", &*mc, &*mf)] {
            assert_eq!((c.render_passes(), f.render_passes()), (0, fragment_passes), "{pass} {name}");
            let (a, b) = (images(c, img, &inputs), images(f, img, &inputs));
            assert!(b[1].iter().any(|v| *v > 0), "{pass} {name}: the scene must produce blending weights");
            if *masked {
                let outside =
                    |o: &[u8]| o.chunks(4).zip(img.chunks(4)).zip(&mask).all(|((o, i), m)| *m >= 128 || o == i);
                assert!(outside(&a[2]), "{pass} {name}: pixels outside the mask must leave the pass unchanged");
            }
            for (k, what) in ["edges", "weights", "output"].iter().enumerate() {
                let differ = a[k].iter().zip(&b[k]).filter(|(x, y)| x != y).count();
                assert_eq!(
                    differ, 0,
                    "{pass} {name}: {what} differ in {differ} bytes between compute ({format:?} edges) and fragment"
                );
            }
        }
    }
}

/// SMAA S2x, T2x and 4x (and 1x through the modes) write the same bytes in both pass shapes, frame after frame
/// (the per-sample SMAA passes, the S2x average and the temporal resolve, reprojected and plain), at an odd size;
/// the compute shape records no render pass.
#[test]
fn smaa_modes_compute_and_fragment_passes_write_the_same_bytes() {
    use rtbake::runtime::aa::three_pass::PassShape;
    use rtbake::runtime::moving_scene::{MovingScene, SceneMotion};
    use rtbake::runtime::smaa_modes::{scene_frame, ModeFrame, SmaaMode, SmaaModes, TemporalResolve};
    let g = gpu();
    let luts = baked_smaa();
    let (w, h) = (133u32, 75u32);
    let scene = MovingScene::new(w, h, SceneMotion::DEFAULT).unwrap();
    let runs = SmaaMode::ALL
        .map(|m| (m, TemporalResolve::default()))
        .into_iter()
        .chain([(SmaaMode::T2x, TemporalResolve::Plain)]);
    for (mode, resolve) in runs {
        let build = |shape| SmaaModes::with_shape(&g.device, &g.queue, (w, h), &luts, (mode, resolve), shape).unwrap();
        let (mut c, mut f) = (build(PassShape::Compute), build(PassShape::Fragment));
        assert_eq!((c.shape(), f.shape()), (PassShape::Compute, PassShape::Fragment));
        let fragment_passes =
            3 * mode.samples_per_frame() as u32 + (mode.samples_per_frame() == 2) as u32 + mode.is_temporal() as u32;
        assert_eq!((c.render_passes(), f.render_passes()), (0, fragment_passes), "{mode:?}");
        for frame in 0..3 {
            let (samples, velocity_px) = scene_frame(&scene, mode, frame);
            let input = ModeFrame { samples: &samples, velocity_px: &velocity_px };
            let a = c.run_frame(&g.device, &g.queue, &input).unwrap();
            let b = f.run_frame(&g.device, &g.queue, &input).unwrap();
            assert!(b != samples[0], "{mode:?} frame {frame}: the pass must change the frame");
            let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
            assert_eq!(
                differ, 0,
                "{mode:?} {resolve:?} frame {frame}: {differ} bytes differ between compute and fragment"
            );
        }
    }
}

#[test]
fn the_pass_shape_is_compute_or_fragment() {
    use rtbake::runtime::aa::three_pass::PassShape;
    assert_eq!(PassShape::parse("compute").unwrap(), PassShape::Compute);
    assert_eq!(PassShape::parse("fragment").unwrap(), PassShape::Fragment);
    let e = PassShape::parse("vertex").unwrap_err().to_string();
    assert!(e.contains("RTBAKE_AA_PASSES") && e.contains("must be compute or fragment, got \"vertex\""), "{e}");
}

/// The compute shape's edge list at its extremes: a flat frame (no edge pixel: an empty indirect dispatch, zero
/// weights, the input unchanged) and a 2048×2048 one-pixel checkerboard (every pixel an edge pixel: 65536 workgroups
/// of 64, more than one dispatch row of 65535), against the fragment shape's bytes.
#[test]
fn the_compute_edge_list_handles_no_edges_and_more_than_one_dispatch_row() {
    use rtbake::runtime::aa::three_pass::PassShape;
    use rtbake::runtime::smaa::SmaaOptions;
    let g = gpu();
    let luts = baked_smaa();
    let read = |t: &wgpu::Texture| rtbake::runtime::gpu::read_texture(&g.device, &g.queue, t).unwrap();
    let run = |(w, h): (u32, u32), img: &[u8], shape| {
        let pass = Smaa::with_shape(&g.device, &g.queue, (w, h), &luts, &SmaaOptions::default(), shape).unwrap();
        let out = pass.run(&g.device, &g.queue, img).unwrap();
        (read(pass.weights()), out)
    };
    let flat = vec![90u8; 64 * 48 * 4];
    let (weights, out) = run((64, 48), &flat, PassShape::Compute);
    assert!(weights.iter().all(|v| *v == 0), "a flat frame has no blending weights");
    assert_eq!(out, flat, "a flat frame leaves SMAA unchanged");
    let n = 2048u32;
    let board: Vec<u8> = (0..n * n)
        .flat_map(|i| if (i % n + i / n).is_multiple_of(2) { [230, 230, 230, 255] } else { [20, 20, 20, 255] })
        .collect();
    let (wc, oc) = run((n, n), &board, PassShape::Compute);
    let (wf, of) = run((n, n), &board, PassShape::Fragment);
    assert!(wf.iter().any(|v| *v > 0), "the checkerboard must produce blending weights");
    assert!(wc == wf, "weights differ in {} bytes", wc.iter().zip(&wf).filter(|(a, b)| a != b).count());
    assert!(oc == of, "outputs differ in {} bytes", oc.iter().zip(&of).filter(|(a, b)| a != b).count());
}

/// SMAA and MLAA recorded into a caller's encoder over a frame already on the device (packed RGBA8 in a storage
/// buffer, as the skin frame's compute chains leave it: `chain::record_antialias`, `ThreePass::encode_on_buffer`)
/// write the bytes of the stand-alone passes (`chain::antialias`: upload, own submission, read-back) in both pass
/// shapes, at an odd size, with one submission and one read-back for the whole encoder; profiled, its passes come
/// back with the bytes of their bounds in either edge format; a buffer too small for the frame is refused naming it.
#[test]
fn antialiasing_recorded_on_a_device_frame_writes_the_bytes_of_the_standalone_pass() {
    use rtbake::image_buf::Image;
    use rtbake::runtime::aa::three_pass::{PassShape, ThreePass};
    use rtbake::runtime::chain::{antialias, record_antialias, Antialiasing};
    use rtbake::runtime::gpu::{map_read, read_backs_on_this_thread, submissions_on_this_thread, submit};
    use rtbake::runtime::mlaa::{Mlaa, MlaaAreaMap, MlaaOptions};
    use rtbake::runtime::moving_scene::{MovingScene, SceneMotion};
    use rtbake::runtime::smaa::SmaaOptions;
    use wgpu::util::DeviceExt;
    let g = gpu();
    let (w, h) = (203u32, 117u32);
    let (luts, map) = (baked_smaa(), MlaaAreaMap::new(33, baked_mlaa(33)).unwrap());
    let moving = MovingScene::new(w, h, SceneMotion::DEFAULT).unwrap().render(1.0, [0.0, 0.0]);
    // Records `record` over `img` uploaded to a storage buffer, copies the buffer out and submits once: the bytes,
    // submissions and read-backs.
    let on_device = |img: &[u8], record: &dyn Fn(&mut wgpu::CommandEncoder, &wgpu::Buffer)| {
        let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let desc = wgpu::util::BufferInitDescriptor { label: Some("frame"), contents: img, usage };
        let frame = g.device.create_buffer_init(&desc);
        let readback = g.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame readback"),
            size: frame.size(),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let (sub, read) = (submissions_on_this_thread(), read_backs_on_this_thread());
        let mut enc = g.device.create_command_encoder(&Default::default());
        record(&mut enc, &frame);
        enc.copy_buffer_to_buffer(&frame, 0, &readback, 0, frame.size());
        submit(&g.queue, enc.finish());
        let bytes = map_read(&g.device, &readback).unwrap();
        (bytes, submissions_on_this_thread() - sub, read_backs_on_this_thread() - read)
    };
    for (scene, img) in [("shapes", render_shapes(w, h, 1)), ("moving scene", moving)] {
        let image = Image::from_vec(w, h, 4, img.clone());
        for (name, aa) in [("SMAA", Antialiasing::Smaa(luts.clone())), ("MLAA", Antialiasing::Mlaa(map.clone()))] {
            let want = antialias(Some(&g), &image, &aa).unwrap().data;
            assert_ne!(want, img, "{name} {scene}: the pass must change the frame");
            let (got, sub, read) =
                on_device(&img, &|enc, frame| record_antialias(&g, enc, frame, (w, h), &aa).unwrap());
            assert_eq!((sub, read), (1, 1), "{name} {scene}: one submission and one read-back");
            let differ = got.iter().zip(&want).filter(|(a, b)| a != b).count();
            assert_eq!(differ, 0, "{name} {scene}: {differ} bytes differ from the stand-alone pass");
            for shape in [PassShape::Compute, PassShape::Fragment] {
                let pass: Box<dyn std::ops::Deref<Target = ThreePass>> = match name {
                    "SMAA" => Box::new(
                        Smaa::with_shape(&g.device, &g.queue, (w, h), &luts, &SmaaOptions::default(), shape).unwrap(),
                    ),
                    _ => Box::new(
                        Mlaa::with_shape(&g.device, &g.queue, (w, h), &map, &MlaaOptions::default(), shape).unwrap(),
                    ),
                };
                let (got, ..) = on_device(&img, &|enc, frame| pass.encode_on_buffer(&g.device, enc, frame).unwrap());
                assert!(got == want, "{name} {scene} {shape:?}: the recorded pass must write the stand-alone bytes");
            }
        }
    }
    // With per-pass profiling on, the three passes come back labelled with their bytes (each image whole and once
    // at its format): 6, 6 and 12 bytes a pixel with `Rg8Unorm` edges, 8, 8 and 12 with `Rgba8Unorm`.
    use rtbake::runtime::gpu::{set_pass_profiling, take_pass_profile};
    let px = (w * h) as u64;
    let fragment = Smaa::with_shape(&g.device, &g.queue, (w, h), &luts, &SmaaOptions::default(), PassShape::Fragment);
    assert_eq!(fragment.unwrap().pass_bytes(), [6 * px, 6 * px, 12 * px], "Rg8Unorm edges");
    for portable in [false, true] {
        rtbake::runtime::aa::three_pass::set_portable_edges(portable);
        let pass = Mlaa::new(&g.device, &g.queue, w, h, &map).unwrap();
        rtbake::runtime::aa::three_pass::set_portable_edges(false);
        let e = match pass.edges().format() {
            wgpu::TextureFormat::Rg8Unorm => 2,
            wgpu::TextureFormat::Rgba8Unorm => 4,
            f => panic!("edges in {f:?}"),
        };
        assert_eq!(e == 4, portable || pass.edges().format() == wgpu::TextureFormat::Rgba8Unorm);
        set_pass_profiling(true);
        on_device(&render_shapes(w, h, 1), &|enc, frame| pass.encode_on_buffer(&g.device, enc, frame).unwrap());
        let profile = take_pass_profile(&g.device, &g.queue).unwrap();
        set_pass_profiling(false);
        let got: Vec<_> = profile.iter().map(|p| (p.label.as_str(), p.bytes)).collect();
        let want = [("mlaa: edges", (4 + e) * px), ("mlaa: weights", (e + 4) * px), ("mlaa: blend", 12 * px)];
        assert_eq!(got, want.map(|(l, b)| (l, Some(b))), "portable {portable}");
    }
    let small = g.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("small"),
        size: 4 * (w * h - 1) as u64,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let pass = Smaa::new(&g.device, &g.queue, w, h, &luts).unwrap();
    let err = pass.encode_on_buffer(&g.device, &mut g.device.create_command_encoder(&Default::default()), &small);
    let err = err.unwrap_err();
    assert_eq!(err.param, "frame");
    assert!(err.message.contains(&format!("{}", 4 * w * h)), "{err}");
}

/// `run demo` with SMAA or MLAA on a device: the shading and the antialiasing are recorded into one encoder, one
/// submission and one read-back for the whole frame, and the frame is byte for byte the one of the shaded frame read
/// back and then antialiased on its own (`chain::antialias`, its own upload, submission and read-back).
#[test]
fn the_antialiased_demo_frame_is_one_submission_with_the_bytes_of_antialiasing_after_the_shading() {
    use rtbake::runtime::chain::{antialias, Antialiasing};
    use rtbake::runtime::demo::{render, DemoAssets, SssMethod};
    use rtbake::runtime::gpu::{read_backs_on_this_thread, submissions_on_this_thread};
    use rtbake::runtime::mlaa::MlaaAreaMap;
    let g = gpu();
    let assets = DemoAssets::load(&baked_dir()).unwrap();
    let (w, h) = (193, 108);
    let aas = [
        ("SMAA", Antialiasing::Smaa(baked_smaa())),
        ("MLAA", Antialiasing::Mlaa(MlaaAreaMap::new(33, baked_mlaa(33)).unwrap())),
    ];
    for (name, aa) in &aas {
        render(Some(&g), w, h, &assets, SssMethod::Separable, Some(aa)).unwrap();
        let (sub, read) = (submissions_on_this_thread(), read_backs_on_this_thread());
        let frame = render(Some(&g), w, h, &assets, SssMethod::Separable, Some(aa)).unwrap();
        let (sub, read) = (submissions_on_this_thread() - sub, read_backs_on_this_thread() - read);
        assert_eq!((sub, read), (1, 1), "{name}: {sub} submissions, {read} read-backs");
        let shaded = render(Some(&g), w, h, &assets, SssMethod::Separable, None).unwrap();
        let want = antialias(Some(&g), &shaded, aa).unwrap();
        assert_ne!(want.data, shaded.data, "{name}: the demo frame has edges to antialias");
        let differ = frame.data.iter().zip(&want.data).filter(|(a, b)| a != b).count();
        assert_eq!(differ, 0, "{name}: {differ} bytes differ from the frame antialiased after its read-back");
    }
}
