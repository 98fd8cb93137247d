//! Neovim's own LSP client (`nvim --headless`, tests/neovim/lsp.lua) against the real
//! `aviary lsp`: diagnostics, hover, definition into the world file and into the standard
//! library, completion, rename
//! and formatting, as a newcomer editing the paper's mission would use them. Runs where
//! `nvim` is installed (.ci/run installs Debian's); elsewhere it says so in one line.

mod common;

use std::process::Command;
use std::time::Duration;

use serde_json::Value;

#[test]
fn neovim_uses_the_language_server() {
    if Command::new("nvim").arg("--version").output().is_err() {
        println!("skipped: nvim is not installed (apt-get install neovim runs it)");
        return;
    }
    let dir = common::scratch("neovim_lsp");
    let repo = common::repo();
    std::fs::copy(repo.join("examples/search_and_rescue.world.toml"), dir.join("paper.world.toml"))
        .unwrap();
    // The paper's mission with a typo and a line out of the canonical layout.
    let paper = std::fs::read_to_string(repo.join("examples/search_and_rescue.mission")).unwrap();
    let edited = paper
        .replacen("video_drone2 FlyTo WITH BuildingB", "video_drone2 FlyTo WITH BuildingC", 1)
        .replacen("sensor_drone TakeOff", "sensor_drone   TakeOff", 1);
    assert_ne!(edited, paper);
    std::fs::write(dir.join("paper.mission"), &edited).unwrap();
    let out = dir.join("seen.json");
    let mut child = Command::new("nvim")
        .args(["--headless", "--clean", "-c"])
        .arg(format!("luafile {}", repo.join("crates/aviary-cli/tests/neovim/lsp.lua").display()))
        .arg("paper.mission")
        .current_dir(&dir)
        .env("AVIARY_BIN", env!("CARGO_BIN_EXE_aviary"))
        .env("AVIARY_NVIM_OUT", &out)
        // Where the server writes the standard library for go to definition.
        .env("XDG_CACHE_HOME", dir.join("cache"))
        .spawn()
        .expect("start nvim");
    let code = common::wait_at_most(&mut child, Duration::from_secs(120), "nvim --headless");
    assert_eq!(code, 0);
    let seen: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert!(seen.get("error").is_none(), "{seen:#}");

    let diagnostics: Vec<&str> =
        seen["diagnostics"].as_array().unwrap().iter().map(|d| d.as_str().unwrap()).collect();
    assert!(
        diagnostics
            .contains(&"19:36 E103 unknown place `BuildingC`\nhelp: did you mean `BuildingA`?"),
        "{diagnostics:#?}"
    );
    let hover = seen["hover"].as_str().unwrap();
    assert!(hover.contains("CAPABILITY FlyCircle BY drone WITH center, radius, laps"), "{hover}");
    assert!(hover.contains("`laps`: a plain number, default `1`"), "{hover}");
    assert!(seen["definition"]["uri"].as_str().unwrap().ends_with("/paper.world.toml"), "{seen:#}");
    assert_eq!(seen["definition"]["line"], 10, "BuildingA is on the world file's line 11");
    // FlyCircle's definition: the standard library's file, at its CAPABILITY line.
    let std = seen["std"]["name"].as_str().unwrap();
    assert!(
        std.starts_with(dir.join("cache/aviary").to_str().unwrap())
            && std.ends_with("/standard.mission"),
        "{seen:#}"
    );
    assert_eq!(std::fs::read_to_string(std).unwrap(), aviary_check::STD_SOURCE);
    assert!(seen["std"]["line"].as_str().unwrap().starts_with("CAPABILITY FlyCircle BY drone"));
    let completion: Vec<&str> =
        seen["completion"].as_array().unwrap().iter().map(|c| c.as_str().unwrap()).collect();
    for wanted in ["center=", "radius=", "laps=", "BuildingA", "Area1"] {
        assert!(completion.contains(&wanted), "{wanted} in {completion:?}");
    }
    // Renamed everywhere, then put in the canonical layout.
    let text = seen["text"].as_str().unwrap();
    let expected = edited.replace("Video2_Ready", "Camera2_Ready").replacen(
        "sensor_drone   TakeOff",
        "sensor_drone TakeOff",
        1,
    );
    assert_eq!(text, expected);
    assert_eq!(text.matches("Camera2_Ready").count(), 2);
}
