#!/usr/bin/env bash
# The Debian packages the checks of `make test` need beside the Python environment, installed where
# the user may (root, or sudo without a password); otherwise stop early naming them. The one list of
# system packages: `make sysdeps` (a prerequisite of `make test`) and .ci/run both call this script.
#   chromium          - the headless browser check of the built book (tests/test_book_browser.py)
#   fonts-wqy-zenhei  - a CJK font, so the Chinese terms of the sources render in that check
#   texlive-latex-base - pdflatex: every tables/*.tex compiles in a plain article (tests/test_tex_exports.py)
#   latex-cjk-common, latex-cjk-chinese-arphic-gbsn00lp, -bsmi00lp - CJKutf8 and its Chinese fonts gbsn
#                       (GB 2312) and bsmi (Big5, for traditional forms), which the exports with Chinese
#                       text name in their header
#   poppler-utils     - pdftotext: the text of the compiled exports is compared with the CSVs
set -euo pipefail

missing_recommends=()   # installed with their recommended packages (chromium's fonts and sandbox)
missing_plain=()        # installed without (texlive's recommendations are hundreds of MB)
command -v chromium >/dev/null 2>&1 || missing_recommends+=(chromium)
if ! { fc-list 2>/dev/null | grep -qi "wenquanyi"; } && [ ! -e /usr/share/fonts/truetype/wqy/wqy-zenhei.ttc ]; then
    missing_recommends+=(fonts-wqy-zenhei)
fi
command -v pdflatex >/dev/null 2>&1 || missing_plain+=(texlive-latex-base)
{ command -v kpsewhich >/dev/null 2>&1 && kpsewhich CJKutf8.sty >/dev/null 2>&1; } || missing_plain+=(latex-cjk-common)
{ command -v kpsewhich >/dev/null 2>&1 && kpsewhich c70gbsn.fd >/dev/null 2>&1; } || missing_plain+=(latex-cjk-chinese-arphic-gbsn00lp)
{ command -v kpsewhich >/dev/null 2>&1 && kpsewhich c70bsmi.fd >/dev/null 2>&1; } || missing_plain+=(latex-cjk-chinese-arphic-bsmi00lp)
command -v pdftotext >/dev/null 2>&1 || missing_plain+=(poppler-utils)
missing=("${missing_recommends[@]}" "${missing_plain[@]}")
[ "${#missing[@]}" -eq 0 ] && exit 0

if [ "$(id -u)" = 0 ]; then
    SUDO=()
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    SUDO=(sudo -n)
else
    echo "make test needs the Debian packages: ${missing[*]}" >&2
    echo "this user can neither install them (not root, no sudo without a password): ask an administrator for" >&2
    echo "    apt-get install ${missing[*]}" >&2
    exit 1
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "make test needs what these Debian packages provide: ${missing[*]} (chromium, a CJK font, pdflatex with CJKutf8 and the gbsn and bsmi fonts, pdftotext);" >&2
    echo "this system has no apt-get: install the equivalents with its own package manager" >&2
    exit 1
fi
echo "installing the Debian packages the checks need: ${missing[*]}"
"${SUDO[@]}" apt-get update -qq
if [ "${#missing_recommends[@]}" -gt 0 ]; then
    "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing_recommends[@]}" >/dev/null
fi
if [ "${#missing_plain[@]}" -gt 0 ]; then
    "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        "${missing_plain[@]}" >/dev/null
fi
