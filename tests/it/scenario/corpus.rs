//! The corpus in `scenarios/`: every file runs through the runner and every expectation
//! holds (CI also runs it through the `hooke` command). It is the project's regression
//! corpus: a file that pins its final-state hash fails when results change.

use hooke::tools::scenario::Scenario;

#[test]
fn every_corpus_scenario_passes() {
    let dir = format!("{}/scenarios", env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    files.sort();
    assert!(files.len() >= 15, "the corpus has {} files", files.len());
    let mut failed = Vec::new();
    for f in &files {
        let report = Scenario::from_file(f)
            .unwrap_or_else(|e| panic!("{e}"))
            .run()
            .unwrap_or_else(|e| panic!("{e}"));
        println!("{report}");
        if !report.passed() {
            failed.push(report.file.clone());
        }
    }
    assert!(failed.is_empty(), "failed: {failed:?}");
}

#[test]
fn a_corpus_scenario_gives_the_same_hash_every_run() {
    let path = format!(
        "{}/scenarios/knock_over_tower.ron",
        env!("CARGO_MANIFEST_DIR")
    );
    let s = Scenario::from_file(path).unwrap();
    let (a, b) = (s.run().unwrap(), s.run().unwrap());
    assert_eq!(a.hash, b.hash);
    assert!(a.passed());
}
