#!/usr/bin/env bash
# Regenerates docs/reference/*.md from the code (`dicestack reference PAGE`), keeping each page's
# hand-written version history: the generated part is replaced, the history is kept as it is.
# Usage: scripts/regenerate-reference.sh [path/to/dicestack]   (default: build/apps/dicestack)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
exe="${1:-$root/build/apps/dicestack}"
[[ -x "$exe" ]] || { echo "regenerate-reference: no dicestack at $exe (build first, or name it)" >&2; exit 1; }
for page in cli learners perturbations regressors world-config; do
  file="$root/docs/reference/$page.md"
  tmp="$(mktemp "$file.XXXXXX")"
  trap 'rm -f "$tmp"' EXIT
  "$exe" reference "$page" > "$tmp"
  if [[ -f "$file" ]] && grep -q '^## Version history$' "$file"; then
    printf '\n' >> "$tmp"
    sed -n '/^## Version history$/,$p' "$file" >> "$tmp"
  fi
  chmod 644 "$tmp"  # mktemp makes it owner-only
  mv "$tmp" "$file"
  trap - EXIT
  echo "wrote $file"
done
