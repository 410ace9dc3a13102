//! Packing policies/hexa_hover, and refusing bad policy folders with the file and field at
//! fault, writing nothing.
// Test code: a failed setup is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use flyloop_fmu_policy::pack::{fmi3_path, pack};
use serde_json::Value;
use std::fs;
use std::path::{Path, PathBuf};

fn shipped() -> PathBuf {
    policy("hexa_hover")
}

/// A shipped policy folder (policies/NAME).
fn policy(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../policies")
        .join(name)
}

/// A fresh folder holding the shipped hover policy's recipe.json and model.onnx.
fn copy_of_shipped(name: &str) -> PathBuf {
    copy_of(&shipped(), name)
}

/// A fresh folder holding `from`'s recipe.json and model.onnx.
fn copy_of(from: &Path, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("flyloop-policy-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    for file in ["recipe.json", "model.onnx"] {
        fs::copy(from.join(file), dir.join(file)).unwrap();
    }
    dir
}

fn edit_recipe(dir: &Path, edit: impl FnOnce(&mut Value)) {
    let path = dir.join("recipe.json");
    let mut recipe: Value = serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
    edit(&mut recipe);
    fs::write(&path, serde_json::to_string(&recipe).unwrap()).unwrap();
}

/// Any existing file stands in for the library: the folder is refused before it is read.
fn library() -> PathBuf {
    shipped().join("model.onnx")
}

fn refused(dir: &Path) -> String {
    let out = dir.join("Policy.fmu");
    let error = pack(dir, &library(), &out)
        .expect_err("a bad folder is refused")
        .to_string();
    assert!(
        !out.exists() && !fmi3_path(&out).exists(),
        "no FMU written: {error}"
    );
    let left: Vec<_> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(
        left.iter().all(|f| !f.to_string_lossy().contains("fmu")),
        "{left:?}"
    );
    error
}

#[test]
fn a_folder_without_a_recipe_is_refused_naming_the_file() {
    let dir = copy_of_shipped("no-recipe");
    fs::remove_file(dir.join("recipe.json")).unwrap();
    let error = refused(&dir);
    assert!(
        error.contains("recipe.json") && error.contains("cannot be read"),
        "{error}"
    );
}

#[test]
fn a_folder_without_its_network_is_refused_naming_the_file() {
    let dir = copy_of_shipped("no-network");
    fs::remove_file(dir.join("model.onnx")).unwrap();
    let error = refused(&dir);
    assert!(error.contains("model.onnx"), "{error}");
}

#[test]
fn a_network_whose_input_size_is_not_the_recipes_is_refused_naming_the_input() {
    // The recipe of a quad (4 motors: 33 observation values) with the hexa's network (37).
    let dir = copy_of_shipped("input-size");
    edit_recipe(&dir, |r| {
        r["rotors"] = 4.into();
        r["layout"][8][1] = 4.into();
        r["layout"][9][1] = 4.into();
        for field in [
            "observation_low",
            "observation_high",
            "observation_mean",
            "observation_var",
        ] {
            let values = r[field].as_array_mut().unwrap();
            values.drain(29..31);
            values.truncate(33);
        }
        for field in ["action_gradient", "action_intercept"] {
            r[field].as_array_mut().unwrap().truncate(4);
        }
    });
    let error = refused(&dir);
    assert!(
        error.contains(
            "model.onnx: input \"observation\": takes 37 values; the recipe's observation has 33"
        ),
        "{error}"
    );
}

#[test]
fn a_recipe_field_out_of_bounds_is_refused_naming_the_field() {
    let cases: [(&str, Value, &str); 4] = [
        (
            "sample_period",
            Value::from(0.0),
            "sample_period: 0 is not > 0 s",
        ),
        ("rotors", Value::from(2), "rotors: 2 is not in [4, 12]"),
        (
            "observation",
            Value::from("lander"),
            "observation: \"lander\"",
        ),
        (
            "network",
            Value::from("../model.onnx"),
            "network: \"../model.onnx\" is not a file name",
        ),
    ];
    for (field, value, expected) in cases {
        let dir = copy_of_shipped(&format!("field-{field}"));
        edit_recipe(&dir, |r| r[field] = value);
        let error = refused(&dir);
        assert!(
            error.contains("recipe.json: ") && error.contains(expected),
            "{error}"
        );
    }
    let dir = copy_of_shipped("short-mean");
    edit_recipe(&dir, |r| {
        r["observation_mean"].as_array_mut().unwrap().pop();
    });
    let error = refused(&dir);
    assert!(
        error.contains("observation_mean: has 36 values, the recipe needs 37"),
        "{error}"
    );
}

#[test]
fn the_shipped_hover_policy_packs_into_both_fmi_versions_with_its_resources() {
    let dir = copy_of_shipped("pack");
    let out = dir.join("HexaHoverPolicy.fmu");
    let paths = pack(&shipped(), &library(), &out).unwrap();
    assert_eq!(paths, [out.clone(), fmi3_path(&out)]);
    for path in &paths {
        let bytes = fs::read(path).unwrap();
        let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
        let names: Vec<String> = zip.file_names().map(str::to_string).collect();
        for want in [
            "modelDescription.xml",
            "resources/recipe.json",
            "resources/model.onnx",
        ] {
            assert!(names.iter().any(|n| n == want), "{want} in {names:?}");
        }
        let mut xml = String::new();
        std::io::Read::read_to_string(&mut zip.by_name("modelDescription.xml").unwrap(), &mut xml)
            .unwrap();
        for name in [
            "\"target_z\"",
            "\"dwz\"",
            "\"motor_state_5\"",
            // FMI 2.0: motor_command_0..5; FMI 3.0: the array motor_command.
            "\"motor_command",
        ] {
            assert!(xml.contains(name), "{name}");
        }
    }
}

#[test]
fn the_offboard_rates_policy_packs_with_the_setpoint_as_its_outputs() {
    let dir = copy_of(&policy("px4_offboard_hover"), "offboard-pack");
    let out = dir.join("OffboardPolicy.fmu");
    let paths = pack(&policy("px4_offboard_hover"), &library(), &out).unwrap();
    for path in &paths {
        let bytes = fs::read(path).unwrap();
        let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
        let mut xml = String::new();
        std::io::Read::read_to_string(&mut zip.by_name("modelDescription.xml").unwrap(), &mut xml)
            .unwrap();
        // The plant's position, velocity, attitude and rates in; RateController's setpoint out.
        for name in [
            "\"qw\"",
            "\"wz\"",
            "\"thrust\"",
            "\"yaw_rate\"",
            "\"target_x\"",
        ] {
            assert!(xml.contains(name), "{name} in {}", path.display());
        }
        for absent in ["\"motor_command", "\"motor_state", "\"dwx\"", "\"wind_x\""] {
            assert!(!xml.contains(absent), "{absent} in {}", path.display());
        }
    }
}

#[test]
fn a_rates_recipe_that_does_not_fit_is_refused_naming_the_field() {
    let offboard = policy("px4_offboard_hover");
    let cases: [(&str, Value, &str); 4] = [
        (
            "rotors",
            Value::from(4),
            "rotors: 4: a rates-estimate policy commands RateController.fmu",
        ),
        (
            "action_map",
            Value::from("linear"),
            "action_map: \"linear\" is not one of",
        ),
        (
            "action_gradient",
            Value::from(vec![1.0; 4]),
            "action_gradient: has 4 values, the recipe needs 0",
        ),
        (
            "action_low",
            Value::from(vec![0.0, -4.0, -4.0]),
            "action_low: has 3 values, the recipe needs 4",
        ),
    ];
    for (field, value, expected) in cases {
        let dir = copy_of(&offboard, &format!("rates-{field}"));
        edit_recipe(&dir, |r| r[field] = value);
        let error = refused(&dir);
        assert!(
            error.contains("recipe.json: ") && error.contains(expected),
            "{error}"
        );
    }
    // The offboard recipe (16 observation values) with the hexa's network (37 in, 6 out).
    let dir = copy_of(&offboard, "rates-network");
    fs::copy(shipped().join("model.onnx"), dir.join("model.onnx")).unwrap();
    let error = refused(&dir);
    assert!(
        error.contains(
            "model.onnx: input \"observation\": takes 37 values; the recipe's observation has 16"
        ),
        "{error}"
    );
}
