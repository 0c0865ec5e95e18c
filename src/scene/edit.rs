//! Reading and changing a loaded scene by its scene-file keys
//! (`camera.fov`, `lights[0].color`, `materials.glass.ior`,
//! `octree.max_depth`), held to the limits scene files are held to and
//! refused with the same words. What can change is what an export's
//! record reproduces: the camera, the octree, lights and materials (as
//! edits); never the geometry.

use crate::limits::{
    INTENSITY_RANGE, IOR_RANGE, MAX_DUPLICATION_RANGE, MAX_LEAF_SIZE, MAX_MEMORY_BUDGET_MIB,
    MAX_OCTREE_DEPTH, SHININESS_RANGE, UNIT_RANGE, check_color, check_finite, check_finite_vec3,
    check_integer, check_range,
};
use crate::math::DVec3;

use super::model::Scene;

/// A key's value, as a scene file writes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KeyValue {
    Number(f64),
    /// A point, a direction or a colour.
    Triple([f64; 3]),
    Integer(i64),
    Switch(bool),
}

/// A key that does not exist, or a value it refuses.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("`{key}`: {message}")]
pub struct EditError {
    pub key: String,
    pub message: String,
}

/// The keys of a material, in the order scene files list them.
pub const MATERIAL_KEYS: [&str; 7] = [
    "color",
    "kd",
    "ks",
    "shininess",
    "reflectivity",
    "transparency",
    "ior",
];

/// The keys of the camera, of a light and of the octree.
pub const CAMERA_KEYS: [&str; 4] = ["eye", "lookat", "up", "fov"];
pub const LIGHT_KEYS: [&str; 2] = ["position", "color"];
pub const OCTREE_KEYS: [&str; 6] = [
    "enabled",
    "max_depth",
    "leaf_size",
    "cost_driven",
    "max_duplication",
    "memory_budget_mib",
];

/// Where a key points.
enum Slot<'k> {
    Camera(&'k str),
    Light(usize, &'k str),
    Material(usize, &'k str),
    Octree(&'k str),
}

impl KeyValue {
    fn number(self) -> Result<f64, String> {
        match self {
            KeyValue::Number(x) => Ok(x),
            KeyValue::Integer(n) => Ok(n as f64),
            _ => Err("expected a number".into()),
        }
    }

    fn triple(self) -> Result<DVec3, String> {
        match self {
            KeyValue::Triple(t) => Ok(DVec3::from_array(t)),
            _ => Err("expected three numbers".into()),
        }
    }

    fn integer(self) -> Result<i64, String> {
        match self {
            KeyValue::Integer(n) => Ok(n),
            _ => Err("expected a whole number".into()),
        }
    }

    fn switch(self) -> Result<bool, String> {
        match self {
            KeyValue::Switch(b) => Ok(b),
            _ => Err("expected true or false".into()),
        }
    }
}

impl Scene {
    /// The value of `key`.
    pub fn get_key(&self, key: &str) -> Result<KeyValue, EditError> {
        let fail = |message: String| EditError {
            key: key.to_owned(),
            message,
        };
        let triple = |v: DVec3| KeyValue::Triple(v.to_array());
        let params = &self.octree_params;
        Ok(match self.slot(key).map_err(fail)? {
            Slot::Camera("eye") => triple(self.camera.eye),
            Slot::Camera("lookat") => triple(self.camera.lookat),
            Slot::Camera("up") => triple(self.camera.up),
            Slot::Camera(_) => KeyValue::Number(self.camera.fov),
            Slot::Light(i, "position") => triple(self.lights[i].position),
            Slot::Light(i, _) => triple(self.lights[i].color),
            Slot::Material(i, field) => {
                let m = &self.materials[i];
                match field {
                    "color" => triple(m.color),
                    "kd" => KeyValue::Number(m.kd),
                    "ks" => KeyValue::Number(m.ks),
                    "shininess" => KeyValue::Number(m.shininess),
                    "reflectivity" => KeyValue::Number(m.reflectivity),
                    "transparency" => KeyValue::Number(m.transparency),
                    _ => KeyValue::Number(m.ior),
                }
            }
            Slot::Octree("enabled") => KeyValue::Switch(self.octree_enabled),
            Slot::Octree("max_depth") => KeyValue::Integer(params.max_depth.into()),
            Slot::Octree("leaf_size") => KeyValue::Integer(params.leaf_size.into()),
            Slot::Octree("cost_driven") => KeyValue::Switch(params.cost_driven),
            Slot::Octree("max_duplication") => KeyValue::Integer(params.max_duplication.into()),
            Slot::Octree(_) => KeyValue::Integer(params.memory_budget_mib.into()),
        })
    }

    /// Sets `key` to `value`, or leaves the scene as it was and says why
    /// not, as a scene file with that value would be refused.
    pub fn set_key(&mut self, key: &str, value: KeyValue) -> Result<(), EditError> {
        let fail = |message: String| EditError {
            key: key.to_owned(),
            message,
        };
        match self.slot(key).map_err(fail)? {
            Slot::Camera(field) => {
                let mut camera = self.camera;
                match field {
                    "eye" => camera.eye = finite_triple(value).map_err(fail)?,
                    "lookat" => camera.lookat = finite_triple(value).map_err(fail)?,
                    "up" => camera.up = finite_triple(value).map_err(fail)?,
                    _ => camera.fov = value.number().and_then(check_finite).map_err(fail)?,
                }
                // A camera that cannot see is refused at the key that
                // makes it so, as a scene file's is.
                camera.check().map_err(|(at, message)| EditError {
                    key: format!("camera.{at}"),
                    message,
                })?;
                self.camera = camera;
            }
            Slot::Light(i, "position") => {
                self.lights[i].position = finite_triple(value).map_err(fail)?;
            }
            Slot::Light(i, _) => {
                self.lights[i].color = color(value, &INTENSITY_RANGE).map_err(fail)?;
            }
            Slot::Material(i, field) => {
                let m = &mut self.materials[i];
                let (slot, range) = match field {
                    "color" => {
                        m.color = color(value, &UNIT_RANGE).map_err(fail)?;
                        return Ok(());
                    }
                    "kd" => (&mut m.kd, &UNIT_RANGE),
                    "ks" => (&mut m.ks, &UNIT_RANGE),
                    "shininess" => (&mut m.shininess, &SHININESS_RANGE),
                    "reflectivity" => (&mut m.reflectivity, &UNIT_RANGE),
                    "transparency" => (&mut m.transparency, &UNIT_RANGE),
                    _ => (&mut m.ior, &IOR_RANGE),
                };
                *slot = value
                    .number()
                    .and_then(check_finite)
                    .and_then(|x| check_range(x, range))
                    .map_err(fail)?;
            }
            Slot::Octree(field) => {
                let params = &mut self.octree_params;
                let integer = |range: std::ops::RangeInclusive<u32>| {
                    let range = i64::from(*range.start())..=i64::from(*range.end());
                    value
                        .integer()
                        .and_then(|n| check_integer(n, &range))
                        .map_err(fail)
                };
                match field {
                    "enabled" => self.octree_enabled = value.switch().map_err(fail)?,
                    "max_depth" => params.max_depth = integer(0..=MAX_OCTREE_DEPTH)?,
                    "leaf_size" => params.leaf_size = integer(1..=MAX_LEAF_SIZE)?,
                    "cost_driven" => params.cost_driven = value.switch().map_err(fail)?,
                    "max_duplication" => {
                        params.max_duplication = integer(MAX_DUPLICATION_RANGE)?;
                    }
                    _ => params.memory_budget_mib = integer(1..=MAX_MEMORY_BUDGET_MIB)?,
                }
            }
        }
        Ok(())
    }

    /// Every key [`Scene::get_key`] reads, in scene-file order.
    pub fn keys(&self) -> Vec<String> {
        let mut keys: Vec<String> = CAMERA_KEYS.iter().map(|k| format!("camera.{k}")).collect();
        for i in 0..self.lights.len() {
            keys.extend(LIGHT_KEYS.iter().map(|k| format!("lights[{i}].{k}")));
        }
        for m in &self.materials {
            keys.extend(
                MATERIAL_KEYS
                    .iter()
                    .map(|k| format!("materials.{}.{k}", m.name)),
            );
        }
        keys.extend(OCTREE_KEYS.iter().map(|k| format!("octree.{k}")));
        keys
    }

    /// Where `key` points, or why it points nowhere.
    fn slot<'k>(&self, key: &'k str) -> Result<Slot<'k>, String> {
        let field_of = |rest: &str, fields: &[&'static str]| -> Result<(), String> {
            if fields.contains(&rest) {
                Ok(())
            } else {
                Err(format!(
                    "unknown key (expected one of {})",
                    fields.join(", ")
                ))
            }
        };
        if let Some(rest) = key.strip_prefix("camera.") {
            return field_of(rest, &CAMERA_KEYS).map(|_| Slot::Camera(rest));
        }
        if let Some(rest) = key.strip_prefix("octree.") {
            return field_of(rest, &OCTREE_KEYS).map(|_| Slot::Octree(rest));
        }
        if let Some(rest) = key.strip_prefix("lights[") {
            let (index, field) = rest
                .split_once("].")
                .ok_or_else(|| "expected lights[INDEX].FIELD".to_owned())?;
            let count = self.lights.len();
            let i = index
                .parse::<usize>()
                .ok()
                .filter(|&i| i < count)
                .ok_or_else(|| format!("the scene has {count} lights, numbered from 0"))?;
            return field_of(field, &LIGHT_KEYS).map(|_| Slot::Light(i, field));
        }
        if let Some(rest) = key.strip_prefix("materials.") {
            // A material's name may hold dots; its field never does.
            let (name, field) = rest
                .rsplit_once('.')
                .ok_or_else(|| "expected materials.NAME.FIELD".to_owned())?;
            let i = self
                .materials
                .iter()
                .position(|m| m.name == name)
                .ok_or_else(|| {
                    let names: Vec<&str> = self.materials.iter().map(|m| m.name.as_str()).collect();
                    format!(
                        "the scene has no material `{name}` (it has {})",
                        names.join(", ")
                    )
                })?;
            return field_of(field, &MATERIAL_KEYS).map(|_| Slot::Material(i, field));
        }
        Err("unknown key (expected camera.*, lights[i].*, materials.NAME.* or octree.*)".into())
    }
}

fn finite_triple(value: KeyValue) -> Result<DVec3, String> {
    value.triple().and_then(check_finite_vec3)
}

fn color(value: KeyValue, range: &std::ops::RangeInclusive<f64>) -> Result<DVec3, String> {
    finite_triple(value).and_then(|c| check_color(c, range))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/default.toml"),
        )
        .unwrap();
        crate::scene::load_str(
            &text,
            std::path::Path::new("scenes/default.toml"),
            &crate::scene::FileSystem,
        )
        .unwrap()
    }

    /// Every key reads back what it was set to.
    #[test]
    fn every_key_reads_back_what_was_set() {
        let mut s = scene();
        for key in s.keys() {
            let value = s.get_key(&key).unwrap();
            s.set_key(&key, value).unwrap();
            assert_eq!(s.get_key(&key).unwrap(), value, "{key}");
        }
        s.set_key("materials.glass.ior", KeyValue::Number(1.33))
            .unwrap();
        let glass = s.materials.iter().find(|m| m.name == "glass").unwrap();
        assert_eq!(glass.ior, 1.33);
        s.set_key("octree.max_depth", KeyValue::Integer(6)).unwrap();
        assert_eq!(s.octree_params.max_depth, 6);
    }

    /// A refused value leaves the scene as it was, and the message is the
    /// one a scene file with that value gets.
    #[test]
    fn refusals_use_the_scene_files_words_and_change_nothing() {
        let mut s = scene();
        let before = s.clone();
        let refused = |s: &mut Scene, key: &str, value| s.set_key(key, value).unwrap_err();
        let e = refused(&mut s, "materials.glass.kd", KeyValue::Number(2.0));
        assert_eq!(
            e.to_string(),
            "`materials.glass.kd`: must lie in [0, 1], got 2"
        );
        let e = refused(&mut s, "lights[0].color", KeyValue::Triple([0.0, 2e3, 0.0]));
        assert!(
            e.message
                .starts_with("each component must lie in [0, 1000]"),
            "{e}"
        );
        let e = refused(&mut s, "camera.fov", KeyValue::Number(180.0));
        assert_eq!(e.key, "camera.fov");
        let lookat = s.camera.lookat.to_array();
        let e = refused(&mut s, "camera.eye", KeyValue::Triple(lookat));
        assert_eq!(e.key, "camera.eye");
        let e = refused(&mut s, "octree.max_depth", KeyValue::Integer(22));
        assert_eq!(e.message, "must be an integer from 0 to 21, got 22");
        let e = refused(&mut s, "camera.fov", KeyValue::Number(f64::NAN));
        assert_eq!(e.message, "must be a finite number, got NaN");
        let e = refused(&mut s, "lights[9].color", KeyValue::Triple([1.0; 3]));
        assert!(e.message.contains("lights"), "{e}");
        let e = refused(&mut s, "materials.nothing.kd", KeyValue::Number(0.5));
        assert!(e.message.contains("glass"), "{e}");
        let e = refused(&mut s, "materials.glass.ka", KeyValue::Number(0.5));
        assert!(e.message.starts_with("unknown key"), "{e}");
        let e = refused(&mut s, "materials.glass.kd", KeyValue::Triple([0.5; 3]));
        assert_eq!(e.message, "expected a number");
        assert_eq!(s, before);
    }

    /// The same value in a scene file is refused with the same message.
    #[test]
    fn a_scene_file_refuses_the_same_value_alike() {
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/default.toml"),
        )
        .unwrap();
        let text = text.replacen("[octree]", "[octree]\nmax_depth = 30", 1);
        let file_error = crate::scene::load_str(
            &text,
            std::path::Path::new("x.toml"),
            &crate::scene::FileSystem,
        )
        .unwrap_err();
        let edit_error = scene()
            .set_key("octree.max_depth", KeyValue::Integer(30))
            .unwrap_err();
        let crate::scene::SceneError::Invalid { location, message } = file_error else {
            panic!("{file_error}")
        };
        assert_eq!(location.key, edit_error.key);
        assert_eq!(message, edit_error.message);
    }
}
