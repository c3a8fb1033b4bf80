#!/usr/bin/env python3
"""Rebuild tools/corpus/manifest.tsv from the corpus kept outside the repository.

Reads CORPUS/_fetch_log.tsv (repo, path, commit, language, note; one row per
copied file, written while gathering) and hashes each corpus file.  Files with
identical content are listed once (the first one); the duplicates are removed
from the corpus folder with --dedupe, otherwise only reported.

Columns: repo, path, commit (or "-" when the file came from a search excerpt
without a commit), language, sha256 of the stored copy, bytes, note.

Stdlib only.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import os
import sys


def corpus_name(repo: str, path: str) -> str:
    owner, name = repo.split("/", 1)
    return f"{owner}__{name}__{path.replace('/', '__')}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--corpus", default="/work/corpus")
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "manifest.tsv"))
    ap.add_argument("--dedupe", action="store_true", help="delete duplicate copies")
    a = ap.parse_args(argv)

    log = os.path.join(a.corpus, "_fetch_log.tsv")
    rows = []
    with open(log, encoding="utf-8", newline="") as f:
        for r in csv.DictReader(f, delimiter="\t"):
            rows.append(r)

    seen: dict[str, str] = {}
    out_rows = []
    problems = 0
    listed = set()
    for r in rows:
        lang = r["language"]
        fn = corpus_name(r["repo"], r["path"])
        p = os.path.join(a.corpus, lang, fn)
        if not os.path.exists(p):
            print(f"missing: {p}", file=sys.stderr)
            problems += 1
            continue
        if fn in listed:
            continue
        listed.add(fn)
        data = open(p, "rb").read()
        h = hashlib.sha256(data).hexdigest()
        if h in seen:
            print(f"duplicate content: {fn} == {seen[h]}", file=sys.stderr)
            if a.dedupe:
                os.remove(p)
            continue
        seen[h] = fn
        out_rows.append((r["repo"], r["path"], r["commit"] or "-", lang, h,
                         str(len(data)), r.get("note", "") or ""))

    # Files present in the corpus but not in the log.
    for lang in ("lua", "python"):
        d = os.path.join(a.corpus, lang)
        for fn in sorted(os.listdir(d)) if os.path.isdir(d) else []:
            if fn not in listed:
                print(f"not in fetch log: {lang}/{fn}", file=sys.stderr)
                problems += 1

    out_rows.sort(key=lambda x: (x[3], x[0].lower(), x[1]))
    with open(a.out, "w", encoding="utf-8", newline="") as f:
        w = csv.writer(f, delimiter="\t", lineterminator="\n")
        w.writerow(["repo", "path", "commit", "language", "sha256", "bytes", "note"])
        w.writerows(out_rows)
    print(f"{len(out_rows)} files written to {a.out}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
