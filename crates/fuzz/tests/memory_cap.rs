//! The fuzzer's memory cap counts an input that allocates past it as a crash: a
//! model whose sparse accessor of five million positions the loader reads (60 MB,
//! within the loader's own budget) kills a worker capped at 32 MiB, and the
//! supervisor saves that very input and fails the run.

#[test]
fn an_input_that_allocates_past_the_cap_is_a_crash() {
    let dir = tempfile::tempdir().unwrap();
    let seed = dir.path().join("five-million-positions.gltf");
    std::fs::write(
        &seed,
        r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAAAAAIC/", "byteLength": 36}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"componentType": 5126, "count": 5000001, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1],
    "sparse": {"count": 1, "indices": {"bufferView": 0, "componentType": 5125}, "values": {"bufferView": 0}}}]}"#,
    )
    .unwrap();
    let crashes = dir.path().join("crashes");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_gnomon-fuzz"))
        .args(["gltf", "--seconds", "2", "--memory-cap-mb", "32", "--seeds"])
        .arg(&seed)
        .arg("--crashes")
        .arg(&crashes)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "the run must fail: {said}");
    let seed_bytes = std::fs::read(&seed).unwrap();
    let saved = std::fs::read_dir(&crashes).unwrap().filter_map(|e| std::fs::read(e.unwrap().path()).ok());
    assert!(saved.into_iter().any(|c| c == seed_bytes), "the input that died is saved: {said}");
}
