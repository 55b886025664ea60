# Shared by the study tests (sourced). SOURCE_DIR: the package; fail() defined by the caller.
# segment_plate_two_layers.txt (written for these tests): two layers (z 2.50, 2.55 mm) of an ORNL Peregrine-style
# layer file (3DThesis layout, mm, the plate's frame around (199, 19) mm, column 5 a 0/1 laser flag).
STUDY_TEST_JOB="$(cd "$(dirname "${BASH_SOURCE[0]}")/../data" && pwd)/segment_plate_two_layers.txt"

# same_results DIR_A DIR_B: every file of results folder A equals B's, byte for byte (metrics.yaml but the
# process's own peak memory, which differs from run to run; config.yaml but stream.threads, which the local backend
# chooses per case and which changes no result; report.html, which shows both, the same). Adds the files compared to
# COMPARED.
COMPARED=0
same_results() {
  local a=$1 b=$2 f name
  for f in "$a"/*; do
    [ -f "$f" ] || continue
    name=$(basename "$f")
    if [ "$name" = metrics.yaml ] || [ "$name" = config.yaml ] || [ "$name" = report.html ]; then
      # report.html shows both files.
      cmp -s <(grep -v "^peak_memory_bytes\|^  threads: " "$f") <(grep -v "^peak_memory_bytes\|^  threads: " "$b/$name") \
        || fail "$b/$name differs from $a"
    else
      cmp -s "$f" "$b/$name" || fail "$b/$name differs from $a"
    fi
    COMPARED=$((COMPARED + 1))
  done
}
