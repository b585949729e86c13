#!/usr/bin/env bash
# COLMAP on one camera of a EuRoC export (eval/systems/colmap/colmap.yaml, docs/systems.md):
#   run.sh INPUT CALIBRATION OUT THREADS [CAMERA]
# INPUT: the export (mav0/camK/data/<ns>.png); CALIBRATION: the folder whose camK/sensor.yaml hold the
# run's calibration (Kannala-Brandt lens = COLMAP's OPENCV_FISHEYE); OUT: output folder; CAMERA:
# cam0 by default. Features only within 85 deg of the optical axis (COLMAP's fisheye models stop at
# 90 deg). Writes OUT/trajectory.txt: TUM, seconds, world_from_rig of every registered image.
set -euo pipefail
input=$1 calibration=$2 out=$3 threads=$4 camera=${5:-cam0}
here=$(cd "$(dirname "$0")" && pwd)
sensor="$calibration/$camera/sensor.yaml"
# COLMAP orders images by name (the sequential matcher matches each with the next ones in that order):
# link them as zero-padded nanoseconds so that the name order is the time order (9.png < 10.png).
images="$out/images"
rm -rf "$images" "$out/masks" "$out/sparse" "$out/text"
mkdir -p "$images" "$out/masks" "$out/sparse" "$out/text"
for image in "$input/mav0/$camera/data"/*.png; do
  ln -s "$(readlink -f "$image")" "$images/$(printf '%020d' "$((10#$(basename "$image" .png)))").png"
done
params=$(python3 "$here/colmap_helper.py" params "$sensor")
python3 "$here/colmap_helper.py" masks "$sensor" "$images" "$out/masks" 85
rm -f "$out/database.db"
colmap feature_extractor --database_path "$out/database.db" --image_path "$images" \
  --ImageReader.camera_model OPENCV_FISHEYE --ImageReader.single_camera 1 \
  --ImageReader.camera_params "$params" --ImageReader.mask_path "$out/masks" \
  --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads "$threads" --SiftExtraction.max_num_features 2048
colmap sequential_matcher --database_path "$out/database.db" --SiftMatching.use_gpu 0 \
  --SiftMatching.num_threads "$threads" --SequentialMatching.overlap 5 \
  --SequentialMatching.quadratic_overlap 0
colmap mapper --database_path "$out/database.db" --image_path "$images" --output_path "$out/sparse" \
  --Mapper.num_threads "$threads" --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_principal_point 0 \
  --Mapper.ba_refine_extra_params 0
for model in "$out"/sparse/*/; do
  name=$(basename "$model")
  mkdir -p "$out/text/$name"
  colmap model_converter --input_path "$model" --output_path "$out/text/$name" --output_type TXT
done
python3 "$here/colmap_helper.py" tum "$sensor" "$out/text" > "$out/trajectory.txt.tmp"
mv "$out/trajectory.txt.tmp" "$out/trajectory.txt"
