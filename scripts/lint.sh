#!/usr/bin/env bash
# Static checks of the project's own sources: clang-format (no changes allowed) and clang-tidy
# (.clang-tidy at the root). Needs a configured build/ (compile_commands.json). Slow: minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f build/compile_commands.json ] || bash scripts/build.sh >/dev/null
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' | grep -vE '^(build|tests/fuzz/corpus)/')
clang-format --dry-run -Werror "${files[@]}"
mapfile -t units < <(printf '%s\n' "${files[@]}" | grep '\.cpp$')
clang-tidy -p build --quiet "${units[@]}" 2>&1 | grep -E '^(/|error)' | grep -vE '^/usr/' | tee build/clang-tidy.txt
! grep -qE '(warning|error):' build/clang-tidy.txt
