//! Wider vector instructions for the per-pixel loops, chosen when the program starts
//! on a CPU that has them.
//!
//! The binary is built for baseline x86-64, whose vectors hold four `f32`. Most x86-64
//! CPUs made since 2015 also have AVX2, with eight. [`multiversion!`] compiles a
//! function twice, for the baseline and for AVX2, and runs the AVX2 copy when the CPU
//! has it. (Building the whole binary for AVX2 instead, `-C target-cpu=x86-64-v3`, made
//! some loops slower and would not start on older CPUs.)
//!
//! Both copies compute bit-identical results: only the vector width differs. IEEE
//! arithmetic is the same in every lane, and Rust never fuses a multiply and an add
//! unless asked to (`mul_add`). So a run gives the same images on every machine,
//! whichever copy runs; `tests` in this module check that on the real pipeline.

/// Whether [`multiversion!`] functions run their AVX2 copy on this thread.
pub(crate) fn use_avx2() -> bool {
    #[cfg(test)]
    if tests::PORTABLE_ONLY.with(std::cell::Cell::get) {
        return false;
    }
    #[cfg(target_arch = "x86_64")]
    {
        // The standard library caches the CPUID answer: this is one atomic load.
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Defines a function whose body is compiled twice, for baseline x86-64 and for AVX2,
/// and which runs the AVX2 copy when [`use_avx2`] says so.
///
/// Only plain argument names are accepted (no patterns), and no generic parameters.
/// Helpers the body calls should be `#[inline]` (or small), so that they are compiled
/// into both copies rather than called in their baseline form.
macro_rules! multiversion {
    (
        $(#[$attr:meta])*
        $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block
    ) => {
        $(#[$attr])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[inline(always)]
            fn portable($($arg: $ty),*) $(-> $ret)? $body

            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2")]
            fn avx2($($arg: $ty),*) $(-> $ret)? {
                portable($($arg),*)
            }

            #[cfg(target_arch = "x86_64")]
            if $crate::vision::simd::use_avx2() {
                // SAFETY: `avx2` requires nothing but the AVX2 instructions, and the
                // CPU was just checked to have them.
                #[allow(unsafe_code, reason = "calling a function compiled for AVX2 after checking the CPU")]
                let out = unsafe { avx2($($arg),*) };
                return out;
            }
            portable($($arg),*)
        }
    };
}
pub(crate) use multiversion;

#[cfg(test)]
pub(crate) mod tests {
    use std::cell::Cell;
    use std::path::Path;

    use crate::math::Pose;
    use crate::scene::{DiskFiles, LoadOptions, load_scene};
    use crate::vision;
    use crate::{Handle, Sim};

    thread_local! {
        /// Set by [`portable_only`] to run the baseline copies on this thread.
        pub(crate) static PORTABLE_ONLY: Cell<bool> = const { Cell::new(false) };
    }

    /// Runs `f` with every [`multiversion!`] function in its baseline copy.
    pub(crate) fn portable_only<T>(f: impl FnOnce() -> T) -> T {
        PORTABLE_ONLY.with(|p| p.set(true));
        let out = f();
        PORTABLE_ONLY.with(|p| p.set(false));
        out
    }

    /// What BubbleRob's sensor delivers in one frame: RGB, depth bits, packet 1 bits,
    /// and the image after the lab sheet's edge detection.
    type Frame = (Vec<u8>, Vec<u32>, Vec<u64>, Vec<u8>);

    /// BubbleRob's 256 x 256 sensor over a few poses of obstacle 0 (none, far, filling
    /// the view, grazing the near plane), each frame rendered and then edge-detected.
    fn frames() -> Vec<Frame> {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/bubble_rob.toml");
        let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).expect("scene loads");
        let mut w = Sim::new(&model);
        let sensor: Handle = w.world.find("/bubbleRob/visionSensor", None, 0).expect("sensor");
        let obstacle = w.world.find("/obstacle", None, 0).expect("obstacle");
        let mut out = Vec::new();
        for x in [3.0, 0.9, 0.35, 0.2] {
            w.world
                .set_world_pose(obstacle, Pose::translation(x, 0.03, 0.1))
                .expect("pose");
            vision::handle_vision_sensor(&w.world, &mut w.vision, sensor).expect("render");
            let img = w.vision.image(sensor).expect("image");
            let packet1 = img.result().expect("result").packets[0]
                .iter()
                .map(|v| v.to_bits())
                .collect();
            let (rgb, depth) = (img.rgb().to_vec(), img.depth().iter().map(|d| d.to_bits()).collect());
            // What simVision.sensorImgToWorkImg, edgeDetectionOnWorkImg(0.2) and
            // workImgToSensorImg do.
            vision::read(&w.world, &mut w.vision, sensor)
                .expect("to work")
                .rgb_to_work();
            vision::work(&w.world, &mut w.vision, sensor)
                .expect("edges")
                .edge_detection(0.2);
            vision::work_to_sensor(&w.world, &mut w.vision, sensor, true).expect("to sensor");
            let edges = w.vision.image(sensor).expect("image").rgb().to_vec();
            out.push((rgb, depth, packet1, edges));
        }
        out
    }

    #[test]
    fn both_copies_see_the_same_pixels() {
        // On a CPU without AVX2 both runs take the baseline copy, and this only checks
        // that rendering is repeatable.
        let wide = frames();
        let portable = portable_only(frames);
        for (k, (a, b)) in wide.iter().zip(&portable).enumerate() {
            assert!(a.0 == b.0, "frame {k}: RGB differs");
            assert!(a.1 == b.1, "frame {k}: depth differs");
            assert!(a.2 == b.2, "frame {k}: packet 1 differs");
            assert!(a.3 == b.3, "frame {k}: edge image differs");
        }
        // The frames differ from each other, so the comparison above covers drawing.
        assert!(wide.windows(2).all(|f| f[0].0 != f[1].0));
        // Edges were found: the edge image is neither all black nor all white.
        assert!(wide.iter().all(|f| f.3.contains(&0) && f.3.contains(&255)));
    }
}
