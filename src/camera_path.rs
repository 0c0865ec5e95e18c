//! Camera paths and turntables: the cameras of a sequence of frames.
//!
//! A path is a list of keyframes (a camera at a time). Between keys, eye
//! and lookat follow a cubic Hermite spline whose tangents are the
//! Catmull-Rom ones for uneven key times, `(p[i+1] - p[i-1]) / (t[i+1] -
//! t[i-1])` (one-sided at the ends), so the path passes through every key
//! with a continuous velocity. `up` is the keys' unit ups blended linearly
//! and renormalised; the camera basis makes it perpendicular to the view.
//! The field of view is interpolated on `ln tan(fov / 2)`, which maps
//! (0, 180) degrees onto the whole line, so no blend leaves that range.
//! A turntable is a generated path: the eye turns about the axis through
//! lookat along the camera's up, at its distance and height.

use crate::camera::CameraSpec;
use crate::math::DVec3;

/// One key of a camera path: where the camera is at `time` (seconds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keyframe {
    pub time: f64,
    pub camera: CameraSpec,
}

/// Keyframes in strictly increasing time, at least one.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraPath {
    keys: Vec<Keyframe>,
}

/// Why a list of keyframes is not a path, or a path's frames cannot be had.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PathError {
    #[error("a camera path needs at least one keyframe")]
    Empty,
    #[error("keyframe {index}: its time must be a finite number of seconds")]
    TimeNotFinite { index: usize },
    #[error(
        "keyframe {index}: its time {time} s is not after the previous keyframe's {previous} s \
         (keyframes go in increasing time)"
    )]
    TimeOrder {
        index: usize,
        time: f64,
        previous: f64,
    },
    #[error("keyframe {index}: {message}")]
    Camera { index: usize, message: String },
    #[error(
        "the path's camera at {time} s has no valid view ({message}): move the keyframes \
         around it apart"
    )]
    Between { time: f64, message: String },
    #[error("{0}")]
    Timing(String),
}

/// How many frames a sequence has and where they fall in time: any two of
/// frames, frames per second and seconds (the rest follow); see
/// [`FrameTiming::resolve`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTiming {
    pub fps: Option<f64>,
    pub seconds: Option<f64>,
    pub frames: Option<u32>,
}

/// Frames per second when nothing says otherwise (film's rate).
pub const DEFAULT_FPS: f64 = 24.0;
/// Most frames one sequence may have.
pub const MAX_FRAMES: u32 = 1_000_000;

impl FrameTiming {
    /// The frame rate and frame count for a path lasting `duration`
    /// seconds: frame k is at `k / fps` from the start. With frames and no
    /// rate, the frames span `seconds` (default: the path) end to end; with
    /// a rate and no count, as many frames as fit in `seconds` plus the one
    /// at its end.
    pub fn resolve(&self, duration: f64) -> Result<(f64, u32), PathError> {
        let bad = |m: &str| Err(PathError::Timing(m.to_owned()));
        if let Some(f) = self.fps
            && !(f > 0.0 && f <= 1000.0)
        {
            return bad("--fps must lie between 0 and 1000 frames per second");
        }
        if let Some(s) = self.seconds
            && !(0.0..=1e6).contains(&s)
        {
            return bad("--seconds must lie between 0 and 1,000,000");
        }
        if let Some(n) = self.frames
            && !(1..=MAX_FRAMES).contains(&n)
        {
            return bad("--frames must lie between 1 and 1,000,000");
        }
        let seconds = self.seconds.unwrap_or(duration);
        let (fps, frames) = match (self.fps, self.frames) {
            (Some(_), Some(_)) if self.seconds.is_some() => {
                return bad("give at most two of --fps, --seconds and --frames");
            }
            (Some(fps), Some(n)) => (fps, n),
            (None, Some(n)) if n > 1 && self.seconds == Some(0.0) => {
                return bad("--seconds 0 holds one frame: give --frames 1, or more seconds");
            }
            (None, Some(n)) => {
                let fps = if n > 1 && seconds > 0.0 {
                    f64::from(n - 1) / seconds
                } else {
                    DEFAULT_FPS
                };
                (fps, n)
            }
            (fps, None) => {
                let fps = fps.unwrap_or(DEFAULT_FPS);
                // The tolerance keeps a frame that lands on the end by
                // rounding (3 s at 24 fps is 73 frames, not 72).
                let n = (seconds * fps + 1e-9).floor() + 1.0;
                if n > f64::from(MAX_FRAMES) {
                    return bad("that makes more than 1,000,000 frames");
                }
                (fps, n as u32)
            }
        };
        Ok((fps, frames))
    }
}

impl CameraPath {
    /// A path through `keys`, which must have increasing finite times and
    /// cameras that can render.
    pub fn new(keys: Vec<Keyframe>) -> Result<Self, PathError> {
        if keys.is_empty() {
            return Err(PathError::Empty);
        }
        for (index, key) in keys.iter().enumerate() {
            if !key.time.is_finite() {
                return Err(PathError::TimeNotFinite { index });
            }
            if index > 0 && !(key.time > keys[index - 1].time) {
                return Err(PathError::TimeOrder {
                    index,
                    time: key.time,
                    previous: keys[index - 1].time,
                });
            }
            key.camera
                .check()
                .map_err(|(k, message)| PathError::Camera {
                    index,
                    message: format!("{k}: {message}"),
                })?;
        }
        Ok(Self { keys })
    }

    pub fn keys(&self) -> &[Keyframe] {
        &self.keys
    }

    pub fn start(&self) -> f64 {
        self.keys[0].time
    }

    /// Seconds from the first key to the last.
    pub fn duration(&self) -> f64 {
        self.keys[self.keys.len() - 1].time - self.keys[0].time
    }

    /// The camera at `time`; before the first key and after the last, the
    /// camera holds still there.
    pub fn at(&self, time: f64) -> CameraSpec {
        let keys = &self.keys;
        let last = keys.len() - 1;
        if keys.len() == 1 || !(time > keys[0].time) {
            return keys[0].camera;
        }
        if time >= keys[last].time {
            return keys[last].camera;
        }
        // The segment [i, i + 1] holding `time`.
        let i = keys.partition_point(|k| k.time <= time) - 1;
        let (a, b) = (&keys[i], &keys[i + 1]);
        let span = b.time - a.time;
        let s = (time - a.time) / span;
        let tangent = |j: usize, get: &dyn Fn(&Keyframe) -> DVec3| -> DVec3 {
            let (lo, hi) = (j.saturating_sub(1), (j + 1).min(last));
            (get(&keys[hi]) - get(&keys[lo])) / (keys[hi].time - keys[lo].time)
        };
        let hermite = |get: &dyn Fn(&Keyframe) -> DVec3| -> DVec3 {
            let (s2, s3) = (s * s, s * s * s);
            let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
            let h10 = s3 - 2.0 * s2 + s;
            let h01 = -2.0 * s3 + 3.0 * s2;
            let h11 = s3 - s2;
            h00 * get(a)
                + h10 * span * tangent(i, get)
                + h01 * get(b)
                + h11 * span * tangent(i + 1, get)
        };
        let eye = hermite(&|k| k.camera.eye);
        let lookat = hermite(&|k| k.camera.lookat);
        let zoom = |k: &Keyframe| DVec3::splat((k.camera.fov.to_radians() * 0.5).tan().ln());
        let fov = 2.0 * hermite(&zoom).x.exp().atan().to_degrees();
        let blend = a.camera.up.normalize() * (1.0 - s) + b.camera.up.normalize() * s;
        let up = if blend.length() > 1e-6 {
            blend.normalize()
        } else {
            // Opposite ups half way: the nearer key's.
            if s < 0.5 { a.camera.up } else { b.camera.up }
        };
        CameraSpec {
            eye,
            lookat,
            up,
            fov,
        }
    }

    /// The time and camera of every frame `timing` asks for, checked: a
    /// camera the spline makes invalid (eye passing through lookat) is an
    /// error naming its time.
    pub fn frames(&self, timing: &FrameTiming) -> Result<Vec<(f64, CameraSpec)>, PathError> {
        let (fps, count) = timing.resolve(self.duration())?;
        (0..count)
            .map(|k| {
                let time = self.start() + f64::from(k) / fps;
                let camera = self.at(time);
                camera
                    .check()
                    .map(|()| (time, camera))
                    .map_err(|(_, message)| PathError::Between { time, message })
            })
            .collect()
    }
}

/// `frames` cameras evenly around a full turn: the eye turns about the
/// axis through `camera.lookat` along `camera.up`, counter-clockwise seen
/// from above (the right-hand rule about up), keeping its distance and
/// height; frame 0 is `camera` itself.
pub fn turntable(camera: &CameraSpec, frames: u32) -> Vec<CameraSpec> {
    let axis = camera.up.normalize();
    let offset = camera.eye - camera.lookat;
    (0..frames)
        .map(|k| {
            if k == 0 {
                return *camera;
            }
            let angle = std::f64::consts::TAU * f64::from(k) / f64::from(frames);
            let (sin, cos) = angle.sin_cos();
            // Rodrigues' rotation formula.
            let turned =
                offset * cos + axis.cross(offset) * sin + axis * axis.dot(offset) * (1.0 - cos);
            CameraSpec {
                eye: camera.lookat + turned,
                ..*camera
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(eye: DVec3, fov: f64) -> CameraSpec {
        CameraSpec {
            eye,
            lookat: DVec3::ZERO,
            up: DVec3::Y,
            fov,
        }
    }

    fn path() -> CameraPath {
        CameraPath::new(vec![
            Keyframe {
                time: 0.0,
                camera: camera(DVec3::new(0.0, 1.0, 5.0), 40.0),
            },
            Keyframe {
                time: 1.0,
                camera: camera(DVec3::new(5.0, 2.0, 0.0), 60.0),
            },
            Keyframe {
                time: 3.0,
                camera: camera(DVec3::new(0.0, 1.0, -5.0), 20.0),
            },
        ])
        .unwrap()
    }

    #[test]
    fn the_path_passes_through_every_key_and_holds_past_its_ends() {
        let p = path();
        for key in p.keys() {
            let at = p.at(key.time);
            assert!((at.eye - key.camera.eye).length() < 1e-12);
            assert!((at.fov - key.camera.fov).abs() < 1e-9);
        }
        assert_eq!(p.at(-1.0), p.keys()[0].camera);
        assert_eq!(p.at(10.0), p.keys()[2].camera);
    }

    #[test]
    fn the_path_is_smooth_across_a_key() {
        // Catmull-Rom tangents: the velocity on both sides of key 1 agrees.
        let p = path();
        let h = 1e-6;
        let before = (p.at(1.0).eye - p.at(1.0 - h).eye) / h;
        let after = (p.at(1.0 + h).eye - p.at(1.0).eye) / h;
        assert!((before - after).length() < 1e-4, "{before} {after}");
        let expected = (DVec3::new(0.0, 1.0, -5.0) - DVec3::new(0.0, 1.0, 5.0)) / 3.0;
        assert!((before - expected).length() < 1e-4);
    }

    #[test]
    fn fov_stays_inside_its_range_between_extreme_keys() {
        let p = CameraPath::new(vec![
            Keyframe {
                time: 0.0,
                camera: camera(DVec3::Z * 5.0, 0.01),
            },
            Keyframe {
                time: 1.0,
                camera: camera(DVec3::Z * 5.0, 179.0),
            },
            Keyframe {
                time: 2.0,
                camera: camera(DVec3::Z * 5.0, 0.01),
            },
        ])
        .unwrap();
        for k in 0..=200 {
            let fov = p.at(f64::from(k) / 100.0).fov;
            assert!(fov > 0.0 && fov < 180.0, "{fov} at {k}");
        }
    }

    #[test]
    fn opposite_ups_do_not_vanish_half_way() {
        let mut down = camera(DVec3::Z * 5.0, 45.0);
        down.up = -DVec3::Y;
        let p = CameraPath::new(vec![
            Keyframe {
                time: 0.0,
                camera: camera(DVec3::Z * 5.0, 45.0),
            },
            Keyframe {
                time: 1.0,
                camera: down,
            },
        ])
        .unwrap();
        let mid = p.at(0.5);
        assert!(mid.check().is_ok(), "{mid:?}");
    }

    #[test]
    fn bad_keys_are_refused_with_their_index() {
        let key = |time| Keyframe {
            time,
            camera: camera(DVec3::Z, 45.0),
        };
        assert_eq!(CameraPath::new(vec![]), Err(PathError::Empty));
        assert!(matches!(
            CameraPath::new(vec![key(1.0), key(1.0)]),
            Err(PathError::TimeOrder { index: 1, .. })
        ));
        assert!(matches!(
            CameraPath::new(vec![key(f64::NAN)]),
            Err(PathError::TimeNotFinite { index: 0 })
        ));
        let mut bad = key(2.0);
        bad.camera.lookat = bad.camera.eye;
        assert!(matches!(
            CameraPath::new(vec![key(1.0), bad]),
            Err(PathError::Camera { index: 1, .. })
        ));
    }

    #[test]
    fn a_spline_through_lookat_is_an_error_naming_the_time() {
        // Eye passes straight through lookat half way.
        let p = CameraPath::new(vec![
            Keyframe {
                time: 0.0,
                camera: CameraSpec {
                    eye: -DVec3::Z,
                    lookat: DVec3::ZERO,
                    up: DVec3::Y,
                    fov: 45.0,
                },
            },
            Keyframe {
                time: 2.0,
                camera: CameraSpec {
                    eye: DVec3::Z,
                    lookat: DVec3::ZERO,
                    up: DVec3::Y,
                    fov: 45.0,
                },
            },
        ])
        .unwrap();
        let timing = FrameTiming {
            frames: Some(3),
            ..FrameTiming::default()
        };
        let e = p.frames(&timing).unwrap_err();
        assert!(
            matches!(e, PathError::Between { time, .. } if time == 1.0),
            "{e}"
        );
    }

    #[test]
    fn timing_gives_frames_at_even_steps() {
        let t = |fps, seconds, frames| FrameTiming {
            fps,
            seconds,
            frames,
        };
        assert_eq!(t(None, None, None).resolve(3.0).unwrap(), (24.0, 73));
        assert_eq!(t(Some(10.0), None, None).resolve(3.0).unwrap(), (10.0, 31));
        assert_eq!(t(None, None, Some(4)).resolve(3.0).unwrap(), (1.0, 4));
        assert_eq!(t(None, Some(1.0), Some(3)).resolve(3.0).unwrap(), (2.0, 3));
        assert_eq!(
            t(Some(5.0), Some(2.0), None).resolve(3.0).unwrap(),
            (5.0, 11)
        );
        assert_eq!(t(None, None, Some(1)).resolve(0.0).unwrap(), (24.0, 1));
        assert!(t(Some(1.0), Some(1.0), Some(1)).resolve(3.0).is_err());
        assert!(t(None, Some(0.0), Some(2)).resolve(3.0).is_err());
        assert_eq!(t(None, Some(0.0), Some(1)).resolve(3.0).unwrap(), (24.0, 1));
        assert!(t(Some(0.0), None, None).resolve(3.0).is_err());
        assert!(t(None, None, Some(0)).resolve(3.0).is_err());
        assert!(t(Some(1000.0), Some(1e6), None).resolve(3.0).is_err());
        let frames = path().frames(&t(None, None, Some(4))).unwrap();
        assert_eq!(
            frames.iter().map(|f| f.0).collect::<Vec<_>>(),
            [0.0, 1.0, 2.0, 3.0]
        );
    }

    #[test]
    fn a_turntable_keeps_distance_and_height_and_closes_the_turn() {
        let start = CameraSpec {
            eye: DVec3::new(3.0, 2.0, 4.0),
            lookat: DVec3::new(1.0, 0.5, -1.0),
            up: DVec3::new(0.0, 2.0, 0.0),
            fov: 50.0,
        };
        let frames = turntable(&start, 8);
        assert_eq!(frames.len(), 8);
        assert_eq!(frames[0], start);
        let d0 = (start.eye - start.lookat).length();
        for f in &frames {
            assert!(((f.eye - f.lookat).length() - d0).abs() < 1e-12);
            assert!((f.eye.y - start.eye.y).abs() < 1e-12, "height kept");
            assert_eq!((f.lookat, f.up, f.fov), (start.lookat, start.up, start.fov));
        }
        // A quarter turn counter-clockwise seen from +y: the offset
        // (2, 1.5, 5) from lookat becomes (5, 1.5, -2).
        let quarter = frames[2].eye - start.lookat;
        assert!(
            (quarter - DVec3::new(5.0, 1.5, -2.0)).length() < 1e-12,
            "{quarter}"
        );
    }
}
