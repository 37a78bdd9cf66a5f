#!/usr/bin/env bash
# The dicestack tool starts without OpenCV's video and image codecs (FFmpeg, GDAL and the
# libraries they pull in): its render library loads libdicestack_videoio.so, from its own folder,
# only when a video is written. Fails if `ldd` of the tool lists them, or if that module is not
# beside the render library.
set -euo pipefail
exe="$1"
deps="$(ldd "$exe")"
forbidden='lib(opencv_videoio|opencv_imgcodecs|avcodec|avformat|gdal)\.so'
if grep -Eq "$forbidden" <<<"$deps"; then
  echo "FAIL: $exe loads at start:"; grep -E "$forbidden" <<<"$deps"; exit 1
fi
render="$(awk '/libdicestack_render\.so/ {print $3}' <<<"$deps")"
module="$(dirname "$render")/libdicestack_videoio.so"
if [[ ! -f "$module" ]]; then
  echo "FAIL: $module: the video module is not beside $render"; exit 1
fi
module_deps="$(ldd "$module")"
if ! grep -q 'libopencv_videoio\.so' <<<"$module_deps"; then
  echo "FAIL: $module does not load OpenCV's video I/O"; exit 1
fi
echo "ok: $exe starts with $(wc -l <<<"$deps") libraries, none of them a video codec; $module writes videos"
