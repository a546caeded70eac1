#!/usr/bin/env bash
# Builds the documentation site (MkDocs with mkdocs-material, from Debian packages) in strict mode: a broken link
# or a missing image fails it.
#   bash scripts/build-docs.sh [OUTDIR]     # default build/site; open OUTDIR/index.html in a browser
# The test suite runs it (test docs.site). The configuration reference it includes is generated from the schema:
#   build/release/immerse-config-reference > docs/reference/configuration.md
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(realpath -m "${1:-build/site}")
if ! command -v mkdocs >/dev/null; then
  echo "build-docs: mkdocs not found: run scripts/install-deps.sh (Debian packages mkdocs, mkdocs-material)" >&2
  exit 1
fi
mkdocs build --strict --clean --config-file mkdocs.yml --site-dir "$out"
echo "build-docs: site written to $out/index.html"
