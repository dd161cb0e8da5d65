#!/usr/bin/env python3
"""Upstream sources by repository and commit: what `scripts/setup --real-nodes` and
`--ros1-sources` build when no folder of archives is given.

A pin file in the repository (`scripts/sources-ros2.tsv`, `scripts/sources-ros1.tsv`)
names, per archive, the repository, the ref it was taken from, the commit, the paths of the
repository it keeps, and the sha256 of that content (`content`: every kept file's path, executable bit and
bytes, in path order, so it does not depend on how an archive was packed). `fetch` downloads each
repository's tarball at its commit, keeps the paths, checks the content against the pin, and
packs it as `ARCHIVE` (one top folder named like it) into a folder with a MANIFEST.tsv: the folder
the builders take, as CI's offline copy is. Archives already there with the pinned content are
kept, so a second setup downloads nothing.

    scripts/sources.py fetch PINS DEST [--git DIR]  get, check and pack; prints DEST
    scripts/sources.py content ARCHIVE...           the content sha256 of archives (to write pins)

The download address is `$MLAUNCH_SOURCES_URL/OWNER/REPO/archive/COMMIT.tar.gz`, by default
GitHub's; the tests point it at a server on 127.0.0.1. With `--git DIR`, nothing is downloaded:
each repository is a git clone (bare or not) in DIR, as `OWNER/REPO`, `OWNER/REPO.git`,
`OWNER+REPO` or `OWNER+REPO/repo`, and the pinned paths at the commit are taken from it with
`git archive` (a clone that lacks some large files still serves the paths that do not need them).
"""

from __future__ import annotations

import csv
import gzip
import hashlib
import io
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
import urllib.error
import urllib.request
from pathlib import Path

DEFAULT_URL = "https://github.com"
COLUMNS = ("archive", "repo", "ref", "commit", "paths", "content")
MAX_DOWNLOAD = 512 * 1024 * 1024  # the largest pinned tarball is a few MB
TIMEOUT_S = 60


class SourcesError(Exception):
    """A pin, a download or a check that failed: the message says which archive and why."""


def read_pins(path: Path) -> list[dict[str, str]]:
    try:
        with path.open(newline="") as handle:
            rows = list(csv.DictReader(handle, delimiter="\t"))
    except OSError as exc:
        raise SourcesError(f"cannot read {path}: {exc.strerror}") from None
    for number, row in enumerate(rows, 2):
        missing = [c for c in COLUMNS if not row.get(c)]
        if missing:
            raise SourcesError(f"{path}:{number}: no {', '.join(missing)}")
    return rows


def content_digest(root: Path) -> str:
    """sha256 of a tree: each file's path (from root), executable bit and bytes, in path order."""
    digest = hashlib.sha256()
    for path in sorted(p for p in root.rglob("*") if not p.is_dir()):
        rel = path.relative_to(root).as_posix()
        if path.is_symlink():
            digest.update(f"L {rel} {os.readlink(path)}\n".encode())
            continue
        executable = "x" if os.access(path, os.X_OK) else "-"
        digest.update(f"F {rel} {executable} {path.stat().st_size}\n".encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def archive_content(archive: Path) -> str:
    """The content digest of a packed archive's one top folder."""
    with tempfile.TemporaryDirectory() as tmp:
        with tarfile.open(archive) as tar:
            tar.extractall(tmp, filter="data")
        tops = list(Path(tmp).iterdir())
        if len(tops) != 1 or not tops[0].is_dir():
            raise SourcesError(f"{archive}: expected one top folder, found {len(tops)} entries")
        return content_digest(tops[0])


def download(url: str) -> bytes:
    try:
        with urllib.request.urlopen(url, timeout=TIMEOUT_S) as answer:
            data = answer.read(MAX_DOWNLOAD + 1)
    except (urllib.error.URLError, OSError) as exc:
        reason = getattr(exc, "reason", exc)
        raise SourcesError(f"cannot download {url}: {reason}") from None
    if len(data) > MAX_DOWNLOAD:
        raise SourcesError(f"{url}: larger than {MAX_DOWNLOAD} bytes")
    return data


def keep_paths(tarball: bytes, paths: list[str], dest: Path) -> None:
    """Unpack a repository tarball (one top folder) and keep ``paths`` of it under ``dest``."""
    with tempfile.TemporaryDirectory() as tmp:
        try:
            with tarfile.open(fileobj=io.BytesIO(tarball), mode="r:*") as tar:
                tar.extractall(tmp, filter="data")
        except (tarfile.TarError, OSError) as exc:
            raise SourcesError(f"not a readable tarball: {exc}") from None
        tops = [p for p in Path(tmp).iterdir() if p.is_dir()]
        if len(tops) != 1:
            raise SourcesError(f"expected one top folder in the tarball, found {len(tops)}")
        top = tops[0]
        dest.mkdir(parents=True)
        for kept in paths:
            source = top if kept == "." else top / kept
            if not source.exists():
                raise SourcesError(f"the repository has no {kept!r} at this commit")
            if kept == ".":
                shutil.copytree(source, dest, symlinks=True, dirs_exist_ok=True)
            elif source.is_dir():
                shutil.copytree(source, dest / kept, symlinks=True)
            else:
                (dest / kept).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(source, dest / kept)


def pack(folder: Path, archive: Path) -> None:
    """A tar.gz of ``folder`` as its one top folder, the same bytes for the same content."""

    def normalize(info: tarfile.TarInfo) -> tarfile.TarInfo:
        info.uid = info.gid = 0
        info.uname = info.gname = "root"
        info.mtime = 0
        return info

    entries = sorted(folder.rglob("*"))
    tmp = archive.with_suffix(".part")
    with (
        open(tmp, "wb") as raw,
        gzip.GzipFile(fileobj=raw, mode="wb", mtime=0) as zipped,
        tarfile.open(fileobj=zipped, mode="w", format=tarfile.PAX_FORMAT) as tar,
    ):
        tar.add(folder, arcname=folder.name, recursive=False, filter=normalize)
        for path in entries:
            name = f"{folder.name}/{path.relative_to(folder).as_posix()}"
            tar.add(path, arcname=name, recursive=False, filter=normalize)
    tmp.replace(archive)


def git_clone(mirrors: Path, repo: str) -> Path:
    """The clone of ``repo`` (OWNER/REPO) in the folder ``mirrors``, in one of its layouts."""
    owner, name = repo.split("/", 1)
    candidates = [
        mirrors / owner / name,
        mirrors / owner / f"{name}.git",
        mirrors / f"{owner}+{name}",
        mirrors / f"{owner}+{name}" / "repo",
    ]
    for path in candidates:
        if (path / "HEAD").is_file() or (path / ".git").exists():
            return path
    raise SourcesError(
        f"no git clone of {repo} in {mirrors} (looked for {owner}/{name}[.git] and"
        f" {owner}+{name}[/repo])"
    )


def git_tarball(clone: Path, commit: str, paths: list[str]) -> bytes:
    """The pinned paths of ``clone`` at ``commit`` as a tarball with one top folder."""
    command = ["git", "-C", str(clone), "archive", "--format=tar", f"--prefix=src-{commit}/"]
    command += [commit, "--", *paths]
    done = subprocess.run(command, capture_output=True, check=False)
    if done.returncode != 0:
        reason = done.stderr.decode(errors="replace").strip().splitlines()
        raise SourcesError(
            f"git archive of {commit} in {clone} failed: {reason[-1] if reason else 'no reason'}"
        )
    return done.stdout


def fetch(pins_file: Path, dest: Path, base_url: str, mirrors: Path | None = None) -> Path:
    pins = read_pins(pins_file)
    dest.mkdir(parents=True, exist_ok=True)
    rows = []
    for pin in pins:
        archive = dest / pin["archive"]
        if not (archive.is_file() and _has_content(archive, pin["content"])):
            _fetch_one(pin, archive, base_url, mirrors)
        sha = hashlib.sha256(archive.read_bytes()).hexdigest()
        rows.append({**{c: pin[c] for c in COLUMNS if c != "content"}, "sha256": sha})
    with (dest / "MANIFEST.tsv").open("w", newline="") as handle:
        fields = ["archive", "repo", "ref", "commit", "paths", "sha256"]
        writer = csv.DictWriter(handle, fields, delimiter="\t", lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
    return dest


def _has_content(archive: Path, content: str) -> bool:
    try:
        return archive_content(archive) == content
    except (SourcesError, tarfile.TarError, OSError):
        return False


def _fetch_one(pin: dict[str, str], archive: Path, base_url: str, mirrors: Path | None) -> None:
    print(f"sources: {pin['archive']}: {pin['repo']} at {pin['commit'][:12]}", file=sys.stderr)
    if mirrors is None:
        url = f"{base_url.rstrip('/')}/{pin['repo']}/archive/{pin['commit']}.tar.gz"
        tarball = download(url)
    else:
        clone = git_clone(mirrors, pin["repo"])
        url = f"{clone} at {pin['commit']}"
        paths = [p for p in pin["paths"].split() if p != "."]
        tarball = git_tarball(clone, pin["commit"], paths)
    stem = pin["archive"].removesuffix(".tar.gz")
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / stem
        try:
            keep_paths(tarball, pin["paths"].split(), folder)
        except SourcesError as exc:
            raise SourcesError(f"{pin['archive']} ({url}): {exc}") from None
        got = content_digest(folder)
        if got != pin["content"]:
            raise SourcesError(
                f"{pin['archive']}: {pin['repo']} at {pin['commit']} does not hold the pinned"
                f" content (sha256 {got}, pinned {pin['content']}): refusing to build from it"
            )
        pack(folder, archive)


def main(argv: list[str]) -> int:
    try:
        if argv[:1] == ["fetch"] and (len(argv) == 3 or (len(argv) == 5 and argv[3] == "--git")):
            base = os.environ.get("MLAUNCH_SOURCES_URL") or DEFAULT_URL
            mirrors = Path(argv[4]) if len(argv) == 5 else None
            print(fetch(Path(argv[1]), Path(argv[2]), base, mirrors))
            return 0
        if len(argv) >= 2 and argv[0] == "content":
            for name in argv[1:]:
                print(f"{archive_content(Path(name))}\t{name}")
            return 0
    except SourcesError as exc:
        print(f"sources: {exc}", file=sys.stderr)
        return 1
    print(
        "usage: scripts/sources.py fetch PINS DEST [--git DIR] | content ARCHIVE...",
        file=sys.stderr,
    )
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
