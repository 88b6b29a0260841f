#!/usr/bin/env bash
# Fails on any project C++ file that clang-format would change (generated code included: the
# generator formats it with the same style).
# usage: format_check.sh CLANG_FORMAT SOURCE_DIR
set -uo pipefail
clang_format=$1
cd "$2" || exit 1
mapfile -t files < <(find runtime codegen generated identification tests examples -name "*.h" -o -name "*.cc" 2>/dev/null | sort)
[ "${#files[@]}" -gt 0 ] || { echo "no files found"; exit 1; }
bad=0
for f in "${files[@]}"; do
  [ -f "$f" ] || continue
  if ! "$clang_format" --dry-run --Werror --style=file "$f" >/dev/null 2>&1; then
    echo "not formatted: $f   (fix: $clang_format -i --style=file $f)"
    bad=1
  fi
done
[ "$bad" -eq 0 ] && echo "${#files[@]} files formatted"
exit $bad
