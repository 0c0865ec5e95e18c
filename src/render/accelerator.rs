//! What a render's ray queries go through, built once from the scene and
//! the settings: the structure the settings choose (octree, BVH or none),
//! the shapes grouped by plane that shadow rays leaving a plane skip, and
//! the light buffer shadow rays ask first. Every caller (the command line,
//! the benchmarks, the viewer, the Python module) builds it through
//! [`Accelerator::build`], and a [`crate::render::Renderer`] queries it.

use std::sync::Arc;
use std::time::Instant;

use crate::accel::{Bvh, LightBuffer, Octree, OctreeError, PlaneGroups};
use crate::scene::Scene;
use crate::settings::{Accel, RenderSettings};

/// The structure ray queries walk.
#[derive(Clone, Debug)]
pub enum Structure {
    Octree(Arc<Octree>),
    Bvh(Arc<Bvh>),
    /// Every shape for every ray.
    BruteForce,
}

/// Parts a caller already holds, used instead of building them again: the
/// viewer and the Python module keep the scene's octree between renders,
/// a sweep builds its trees with other parameters.
#[derive(Clone, Default)]
pub struct Reuse {
    /// An octree over the scene's shapes (used when the settings ask for
    /// the octree).
    pub octree: Option<Arc<Octree>>,
    /// A BVH over the scene's shapes (used when they ask for the BVH).
    pub bvh: Option<Arc<Bvh>>,
    pub light_buffer: LightBufferSource,
}

impl Reuse {
    /// `octree` and no light buffer: what a thumbnail, a sample of rays
    /// or a pixel's ray tree measures is the tree's own work.
    pub fn octree_alone(octree: &Arc<Octree>) -> Self {
        Self {
            octree: Some(Arc::clone(octree)),
            bvh: None,
            light_buffer: LightBufferSource::Given(None),
        }
    }
}

/// Where the light buffer comes from.
#[derive(Clone, Default)]
pub enum LightBufferSource {
    /// Built here when the render would ask it.
    #[default]
    Build,
    /// This one (or none): a counted render asks none (it would hide the
    /// accelerator's work), and the viewer does not build one again while
    /// a light is dragged. A buffer of other lights is not used.
    Given(Option<Arc<LightBuffer>>),
}

/// A scene of fewer shapes than this whose octree is one leaf (so its
/// uncounted shadow rays go brute force) gets no light buffer: a look-up
/// and a list cost more than testing so few shapes.
const LIGHT_BUFFER_MIN_SHAPES: usize = 5;

/// The built accelerator of one scene with one choice of [`Accel`].
#[derive(Clone)]
pub struct Accelerator {
    structure: Structure,
    /// Whether uncounted queries walk the octree: not a tree that is one
    /// leaf, which holds every bounded shape, so brute force finds the
    /// same hits without the walk's setup. Counted queries always walk,
    /// so Havran's counts stay the tree's.
    walks_uncounted: bool,
    light_buffer: Option<Arc<LightBuffer>>,
    /// Seconds to build the structure here (0 when reused) and the buffer.
    structure_s: f64,
    light_buffer_s: f64,
}

impl Accelerator {
    /// The accelerator `settings.accel` names over `scene`, taking what
    /// `reuse` holds instead of building it; a light buffer when shadow
    /// rays would ask it (shadows on, through the BVH or an octree of more
    /// than one leaf or of five shapes or more).
    pub fn build(
        scene: &Scene,
        settings: &RenderSettings,
        reuse: Reuse,
    ) -> Result<Self, OctreeError> {
        let start = Instant::now();
        let structure = match settings.accel {
            Accel::Octree => Structure::Octree(match reuse.octree {
                Some(tree) => tree,
                None => Arc::new(scene.build_octree()?),
            }),
            Accel::Bvh => Structure::Bvh(
                reuse
                    .bvh
                    .unwrap_or_else(|| Arc::new(Bvh::build(&scene.shapes))),
            ),
            Accel::BruteForce => Structure::BruteForce,
        };
        let structure_s = start.elapsed().as_secs_f64();
        let wants_buffer = settings.shadows
            && match &structure {
                Structure::Bvh(_) => true,
                Structure::Octree(tree) => {
                    !tree.is_one_leaf() || scene.shapes.len() >= LIGHT_BUFFER_MIN_SHAPES
                }
                Structure::BruteForce => false,
            };
        let start = Instant::now();
        let light_buffer = match reuse.light_buffer {
            _ if !wants_buffer => None,
            LightBufferSource::Build => scene.build_light_buffer().map(Arc::new),
            LightBufferSource::Given(buffer) => {
                let lights: Vec<_> = scene.lights.iter().map(|l| l.position).collect();
                buffer.filter(|b| b.fits(scene.shapes.len(), &lights))
            }
        };
        let light_buffer_s = start.elapsed().as_secs_f64();
        Ok(Self {
            walks_uncounted: match &structure {
                Structure::Octree(tree) => !tree.is_one_leaf(),
                _ => false,
            },
            structure,
            light_buffer,
            structure_s,
            light_buffer_s,
        })
    }

    /// Which of the three this is.
    pub fn kind(&self) -> Accel {
        match self.structure {
            Structure::Octree(_) => Accel::Octree,
            Structure::Bvh(_) => Accel::Bvh,
            Structure::BruteForce => Accel::BruteForce,
        }
    }

    pub fn structure(&self) -> &Structure {
        &self.structure
    }

    /// The octree, when queries go through one.
    pub fn octree(&self) -> Option<&Arc<Octree>> {
        match &self.structure {
            Structure::Octree(tree) => Some(tree),
            _ => None,
        }
    }

    /// The BVH, when queries go through one.
    pub fn bvh(&self) -> Option<&Arc<Bvh>> {
        match &self.structure {
            Structure::Bvh(tree) => Some(tree),
            _ => None,
        }
    }

    /// Whether uncounted queries walk the octree (see the field).
    #[inline(always)]
    pub(super) fn walks_uncounted(&self) -> bool {
        self.walks_uncounted
    }

    /// The shapes grouped by the plane they lie in, for shadow rays
    /// leaving one: the structure's (brute force tests every shape).
    pub fn planes(&self) -> Option<&PlaneGroups> {
        match &self.structure {
            Structure::Octree(tree) => Some(tree.planes()),
            Structure::Bvh(tree) => Some(tree.planes()),
            Structure::BruteForce => None,
        }
    }

    /// The light buffer shadow rays ask first, if built.
    pub fn light_buffer(&self) -> Option<&LightBuffer> {
        self.light_buffer.as_deref()
    }

    /// The light buffer, to keep for later renders of the same lights.
    pub fn shared_light_buffer(&self) -> Option<&Arc<LightBuffer>> {
        self.light_buffer.as_ref()
    }

    /// Seconds this build took for the structure (0 when reused) and for
    /// the light buffer.
    pub fn build_seconds(&self) -> (f64, f64) {
        (self.structure_s, self.light_buffer_s)
    }

    /// Bytes of the structure and the light buffer, for the memory check.
    pub fn memory_bytes(&self) -> u64 {
        let structure = match &self.structure {
            Structure::Octree(tree) => tree.stats().memory_bytes,
            Structure::Bvh(tree) => tree.stats().memory_bytes,
            Structure::BruteForce => 0,
        };
        structure
            + self
                .light_buffer
                .as_ref()
                .map_or(0, |b| b.stats().memory_bytes)
    }
}

#[cfg(test)]
impl Accelerator {
    /// `octree` (over `scene`'s shapes) alone, as unit tests query it.
    pub(crate) fn of_octree(scene: &Scene, octree: Octree) -> Self {
        let settings = RenderSettings {
            accel: Accel::Octree,
            ..scene.render_settings()
        };
        Self::build(scene, &settings, Reuse::octree_alone(&Arc::new(octree)))
            .expect("an octree given is not built")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        crate::scene::builtin::default_scene().unwrap()
    }

    #[test]
    fn the_settings_choice_is_what_is_built_and_reused_parts_are_taken() {
        let scene = scene();
        for accel in Accel::ALL {
            let settings = RenderSettings {
                accel,
                ..scene.render_settings()
            };
            let built = Accelerator::build(&scene, &settings, Reuse::default()).unwrap();
            assert_eq!(built.kind(), accel);
            assert_eq!(built.octree().is_some(), accel == Accel::Octree);
            assert_eq!(built.bvh().is_some(), accel == Accel::Bvh);
            // Brute force stays brute force: no buffer, no plane skipping.
            assert_eq!(built.light_buffer().is_some(), accel != Accel::BruteForce);
            assert_eq!(built.planes().is_some(), accel != Accel::BruteForce);
        }
        let settings = scene.render_settings();
        let tree = Arc::new(scene.build_octree().unwrap());
        let reuse = Reuse {
            octree: Some(Arc::clone(&tree)),
            light_buffer: LightBufferSource::Given(None),
            ..Reuse::default()
        };
        let built = Accelerator::build(&scene, &settings, reuse).unwrap();
        assert!(Arc::ptr_eq(built.octree().unwrap(), &tree));
        assert!(built.light_buffer().is_none(), "none given, none built");
        // No shadows, no buffer.
        let dark = RenderSettings {
            shadows: false,
            ..settings
        };
        let built = Accelerator::build(&scene, &dark, Reuse::default()).unwrap();
        assert!(built.light_buffer().is_none());
    }

    #[test]
    fn a_buffer_of_other_lights_is_not_used() {
        let scene = scene();
        let settings = scene.render_settings();
        let buffer = Arc::new(scene.build_light_buffer().unwrap());
        let mut moved = scene.clone();
        moved.lights[0].position += crate::math::DVec3::X;
        let given = |s: &Scene| {
            let reuse = Reuse {
                light_buffer: LightBufferSource::Given(Some(Arc::clone(&buffer))),
                ..Reuse::default()
            };
            Accelerator::build(s, &settings, reuse).unwrap()
        };
        assert!(given(&scene).light_buffer().is_some());
        assert!(given(&moved).light_buffer().is_none());
    }
}
