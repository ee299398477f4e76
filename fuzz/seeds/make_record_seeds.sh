#!/bin/sh
# Writes fuzz/seeds/record_load/: the real records of the record_load target's
# experiment (fuzz/src/record_load.rs, EXPERIMENT), each after its two leading
# bytes (the episode it claims, how many times it is counted). Run from the
# repository's root after `cargo build --release`; wall_ms varies run to run.
set -eu
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sed -n '/^pub const EXPERIMENT: &str = r#"$/,/^"#;$/p' fuzz/src/record_load.rs | sed '1d;$d' > "$tmp/fuzz.toml"
./target/release/cpsplan experiment "$tmp/fuzz.toml" --out "$tmp/out" -q
mkdir -p fuzz/seeds/record_load
for f in "$tmp"/out/records/*.json; do
    i=$(basename "$f" .json)
    i=$(echo "$i" | sed "s/^0*//"); i=${i:-0}
    { printf "\\$(printf '%03o' "$i")\\001"; cat "$f"; } > "fuzz/seeds/record_load/episode-$i"
done
