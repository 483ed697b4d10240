#!/bin/sh
# Renders the animation demo and shows it: writes the flag's OBJ sequence,
# renders frames 1 to 48 to scenes/animation/frames/, and lays them out as
# an animated GIF and a contact sheet. Run from the repository's root:
#   sh scenes/animation/render.sh
set -e
cargo run --release --example cloth -- scenes/animation/cloth
mkdir -p scenes/animation/frames
cargo run --release -- render scenes/animation/demo.yaml --frames 1..48 \
    -o scenes/animation/frames/frame_##.png --skip-existing
cargo run --release -- sheet scenes/animation/frames/frame_##.png --frames 1..48 \
    --every 2 --fps 12 -o scenes/renders/animation.gif
cargo run --release -- sheet scenes/animation/frames/frame_##.png --frames 1..48 \
    --every 6 --columns 4 -o scenes/renders/animation-sheet.png
