//! Rendering: a scene and its octree made into a frame. [`Renderer`] holds
//! a scene prepared for fixed settings; the integrator
//! (`integrator.rs`) finds the colour along one ray; the passes
//! (`passes.rs`) sweep the image tile by tile, progressively and
//! cancellably, for every way glint samples a pixel (one sample, the grid,
//! adaptive refinement, the SPD's corners) and every view. `glint render`,
//! `bench`, `study` and the viewer all render through
//! [`Renderer::render_frame`].

mod accelerator;
pub mod adaptive;
mod corners;
mod integrator;
pub mod memory;
mod packets;
mod passes;
pub mod ray_tree;
pub mod render_cache;
mod sampling;
mod texture_lookups;
mod texturing;
mod tile_job;
pub mod tiles;
mod unit_costs;

mod renderer;

pub use accelerator::{Accelerator, LightBufferSource, Reuse, Structure};
pub use passes::{
    FinishedPass, FinishedTile, PassInfo, PassKind, PassOptions, PassSummary, PassWatch,
    RenderedFrame, pass_settings,
};
pub use renderer::{RenderError, Renderer};
pub use unit_costs::{
    OctreeCandidate, Prediction, RAY_SAMPLE_SIDE, RaySample, SUGGESTION_DEPTHS,
    SUGGESTION_LEAF_SIZES, UnitCosts, random_lines, sample_rays, sample_rays_with, suggest_octree,
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::CameraSpec;
    use crate::image::frame::Frame;
    use crate::limits::{LimitError, MAX_IMAGE_SIDE};
    use crate::material::Light;
    use crate::material::Material;
    use crate::math::DVec3;
    use crate::scene::ImageSettings;
    use crate::scene::Scene;
    use crate::settings::RenderSettings;
    use crate::shapes::{Plane, Shape, Sphere};
    use crate::stats::RenderCounts;

    /// A scene seen from (0, 0, 10) towards the origin, `size` pixels on
    /// a side, lit by one white light at `light`, with these materials.
    fn scene(size: u32, max_depth: u32, materials: Vec<Material>, light: DVec3) -> Scene {
        let mut scene = Scene::empty(
            "unit".into(),
            CameraSpec {
                eye: DVec3::new(0.0, 0.0, 10.0),
                lookat: DVec3::ZERO,
                up: DVec3::Y,
                fov: 20.0,
            },
            ImageSettings {
                width: size,
                height: size,
                samples: 1,
                max_depth,
                background: DVec3::new(0.2, 0.4, 0.6),
                ambient: DVec3::splat(0.25),
                ..ImageSettings::default()
            },
        );
        scene.materials = materials;
        scene.lights = vec![Light {
            position: light,
            color: DVec3::ONE,
        }];
        scene
    }

    fn render(scene: &Scene) -> (Frame, RenderCounts) {
        let accel = crate::render::Accelerator::of_octree(scene, scene.build_octree().unwrap());
        Renderer::new(scene, &accel, scene.render_settings())
            .unwrap()
            .render(false, None)
    }

    fn mirror(reflectivity: f64) -> Material {
        Material {
            ka: 0.0,
            kd: 0.0,
            reflectivity,
            ..Material::default()
        }
    }

    #[test]
    fn a_mirror_facing_the_eye_shows_the_background_times_its_weight() {
        // The centre ray comes straight back and leaves the scene.
        let mut s = scene(3, 5, vec![mirror(0.5)], DVec3::new(0.0, 0.0, 10.0));
        s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
        let (frame, counts) = render(&s);
        let expected = 0.5 * DVec3::new(0.2, 0.4, 0.6);
        assert!(
            (frame.pixels[4] - expected).length() < 1e-12,
            "{}",
            frame.pixels[4]
        );
        assert_eq!(counts.rays.reflection, 9, "one mirror ray per pixel");
    }

    #[test]
    fn facing_mirrors_spawn_one_reflection_per_level_of_depth() {
        // Mirrors at z = 0 and z = 20 with the eye between them: every ray
        // bounces until the depth limit, `max_depth - 1` reflections.
        for max_depth in [1, 2, 5, 9] {
            let mut s = scene(4, max_depth, vec![mirror(1.0)], DVec3::new(0.0, 3.0, 10.0));
            s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
            s.push(
                Shape::Plane(Plane::new(DVec3::new(0.0, 0.0, 20.0), -DVec3::Z)),
                0,
            );
            let (_, counts) = render(&s);
            assert_eq!(counts.rays.primary, 16);
            assert_eq!(
                counts.rays.reflection,
                16 * (max_depth as u64 - 1),
                "max depth {max_depth}"
            );
        }
    }

    #[test]
    fn a_sphere_between_light_and_floor_leaves_only_ambient_below_it() {
        let floor = Material {
            color: DVec3::new(0.9, 0.5, 0.1),
            ka: 1.0,
            kd: 0.7,
            ..Material::default()
        };
        // The sphere halfway from the floor's centre (the centre pixel) to
        // the light, off the eye's line of sight.
        let light = DVec3::new(3.0, 0.0, 6.0);
        let mut s = scene(5, 1, vec![floor.clone()], light);
        s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
        let (lit, _) = render(&s);
        s.push(Shape::Sphere(Sphere::new(light * 0.5, 0.3)), 0);
        let (shadowed, _) = render(&s);
        let ambient = 0.25 * floor.color;
        // Lambert: kd * color * cos, the cosine 6 / |(3, 0, 6)|.
        let direct = 0.7 * floor.color * (6.0 / 45f64.sqrt());
        assert!((lit.pixels[12] - (ambient + direct)).length() < 1e-12);
        assert!(
            (shadowed.pixels[12] - ambient).length() < 1e-12,
            "{} vs {ambient}",
            shadowed.pixels[12]
        );
        // A corner of the floor is out of the shadow: unchanged.
        assert_eq!(shadowed.pixels[0], lit.pixels[0]);
    }

    #[test]
    fn an_index_matched_clear_sphere_is_invisible() {
        // ior 1, fully transparent, no local light: the refracted ray goes
        // straight on, so the picture is the one without the sphere.
        let floor = Material {
            color: DVec3::new(0.3, 0.8, 0.4),
            ..Material::default()
        };
        let glass = Material {
            ka: 0.0,
            kd: 0.0,
            transparency: 1.0,
            ior: 1.0,
            ..Material::default()
        };
        let light = DVec3::new(2.0, 3.0, 9.0);
        let mut s = scene(16, 5, vec![floor, glass], light);
        s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
        let (without, _) = render(&s);
        s.push(
            Shape::Sphere(Sphere::new(DVec3::new(0.0, 0.0, 2.0), 1.0)),
            1,
        );
        let (with, counts) = render(&s);
        assert!(counts.rays.refraction > 0, "rays went through the sphere");
        for (a, b) in with.pixels.iter().zip(&without.pixels) {
            assert!((*a - *b).length() < 1e-9, "{a} vs {b}");
        }
    }

    /// Which settings are refused is `RenderSettings::check`'s test; here,
    /// that the renderer refuses them rather than rendering.
    #[test]
    fn the_renderer_refuses_settings_outside_the_limits() {
        let mut s = scene(4, 5, vec![Material::default()], DVec3::Z);
        s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
        let accel = crate::render::Accelerator::of_octree(&s, s.build_octree().unwrap());
        let base = s.render_settings();
        let with = |settings| Renderer::new(&s, &accel, settings).err();
        assert!(with(base).is_none());
        assert!(matches!(
            with(RenderSettings { samples: 8, ..base }),
            Some(RenderError::Limit(LimitError::Samples(8)))
        ));
        assert!(matches!(
            with(RenderSettings {
                width: MAX_IMAGE_SIDE + 1,
                ..base
            }),
            Some(RenderError::Limit(LimitError::ImageSize(..)))
        ));
    }

    /// Each pass traces what `pass_settings` says it does: its eye rays
    /// are its pixels times its samples (the aa-need view's grid pass
    /// traces the 4x4 grid even at 1 sample), and the engine hands the
    /// same settings to its watcher.
    #[test]
    fn each_pass_traces_what_its_settings_say() {
        use crate::settings::ViewMode;
        struct Seen(std::sync::Mutex<Vec<PassInfo>>);
        impl PassWatch for Seen {
            fn pass_started(&self, pass: &PassInfo) {
                self.0.lock().unwrap().push(*pass);
            }
        }
        let mut s = scene(6, 5, vec![Material::default()], DVec3::Z);
        s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
        let accel = crate::render::Accelerator::of_octree(&s, s.build_octree().unwrap());
        for (samples, view) in [
            (1, ViewMode::Shaded),
            (16, ViewMode::Shaded),
            (1, ViewMode::AaNeed),
            (16, ViewMode::Depth),
        ] {
            let settings = RenderSettings {
                samples,
                view,
                ..s.render_settings()
            };
            let renderer = Renderer::new(&s, &accel, settings).unwrap();
            let seen = Seen(Default::default());
            let options = PassOptions {
                count_work: false,
                progressive: true,
            };
            let frame = renderer.render_frame(options, &seen).unwrap();
            let seen = seen.0.into_inner().unwrap();
            assert_eq!(seen.len(), frame.passes.len());
            for (info, summary) in seen.iter().zip(&frame.passes) {
                let expected = pass_settings(settings, info.kind);
                assert_eq!(info.settings, expected);
                assert_ne!(expected.view, ViewMode::AaNeed);
                let pixels = u64::from(settings.width * settings.height);
                assert_eq!(
                    summary.counts.rays.primary,
                    pixels * u64::from(expected.samples),
                    "{samples} spp {view:?}, {:?}",
                    info.kind
                );
            }
        }
    }
}
