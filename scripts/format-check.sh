#!/usr/bin/env bash
# Checks (or, with --fix, rewrites) the formatting of pixelgym's own C++ files against the
# repository's .clang-format with clang-format 14 (Debian 12's `clang-format` package). Exits 1
# naming the files that differ, 0 when none does, 1 also when clang-format is missing, 2 on other
# errors. Files: *.h, *.cc, *.cpp, *.hpp known to git
# (tracked, or new and not ignored), outside assets/ and build folders.
#   scripts/format-check.sh          check (what `make format-check` and ctest's FormatCheck run)
#   scripts/format-check.sh --fix    rewrite the files in place (`make format`)
set -euo pipefail
cd "$(dirname "$0")/.."

fix=0
if [ "${1:-}" = "--fix" ]; then fix=1; fi

clang_format=""
for candidate in clang-format-14 clang-format; do
  if command -v "$candidate" >/dev/null 2>&1; then clang_format="$candidate"; break; fi
done
if [ -z "$clang_format" ]; then
  # A check that cannot run fails: CI must not pass because the tool went missing.
  echo "format-check: clang-format not found; scripts/install-deps.sh installs it" >&2
  exit 1
fi
version="$("$clang_format" --version)"
case "$version" in
  *"version 14."*) ;;
  *) echo "format-check: warning: expected clang-format 14 (Debian 12), using: $version" >&2 ;;
esac

# The project's own C++ files, NUL-separated.
list_files() {
  if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    git ls-files -z --cached --others --exclude-standard -- '*.h' '*.cc' '*.cpp' '*.hpp' \
      ':!:assets/**' ':!:build/**' ':!:build-*/**'
  else
    find . \( -path ./assets -o -path ./.git -o -path './build*' \) -prune -o -type f \
      \( -name '*.h' -o -name '*.cc' -o -name '*.cpp' -o -name '*.hpp' \) -print0
  fi
}

files=()
while IFS= read -r -d '' file; do
  [ -f "$file" ] && files+=("$file")
done < <(list_files)
if [ ${#files[@]} -eq 0 ]; then
  echo "format-check: no C++ files found" >&2
  exit 2
fi

if [ "$fix" -eq 1 ]; then
  "$clang_format" -i --style=file "${files[@]}"
  echo "format-check: formatted ${#files[@]} files with $clang_format"
  exit 0
fi

# One run over every file; each difference is reported as "FILE:LINE:COL: error: ...".
status=0
report="$("$clang_format" --style=file --dry-run -Werror "${files[@]}" 2>&1)" || status=$?
differ=()
while IFS= read -r file; do
  [ -n "$file" ] && differ+=("$file")
done < <(printf '%s\n' "$report" | sed -n 's/^\(.*\):[0-9][0-9]*:[0-9][0-9]*: error: .*/\1/p' | sort -u)
if [ "$status" -ne 0 ] && [ ${#differ[@]} -eq 0 ]; then
  echo "format-check: $clang_format failed (exit $status) without naming a file:" >&2
  printf '%s\n' "$report" >&2
  exit 2
fi
if [ ${#differ[@]} -ne 0 ]; then
  echo "format-check: ${#differ[@]} of ${#files[@]} C++ files differ from .clang-format ($clang_format):" >&2
  printf '  %s\n' "${differ[@]}" >&2
  echo "format-check: run 'make format' (or clang-format -i FILE) and commit the result" >&2
  exit 1
fi
echo "format-check: all ${#files[@]} C++ files match .clang-format ($clang_format)"
