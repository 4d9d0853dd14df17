"""File names in the order Qt's ``QDir`` lists them, as relight and relight-cli read a folder.

relight lists a folder's images (``Project::scanDir``, ``ImageSet::initFromFolder``) and
relight-cli its ``.lp`` files with a ``QDir``, whose default sort is ``Name | IgnoreCase``:
Qt's ``qdir.cpp`` (``qt_cmp_si``) compares ``fileName().toLower()`` with ``QString::compare``.
Two things there are not Python's ``sorted(key=str.lower)``:

* ``QString::compare`` orders by UTF-16 code units, not code points: a character beyond
  U+FFFF (an emoji, a surrogate pair from 0xD800) comes before one from U+E000 to U+FFFF
  (full-width forms, ligatures such as ``ﬁ``, private-use glyphs);
* ``QString::toLower`` lowers each character on its own, where ``str.lower`` writes a
  word-final capital sigma as ``ς`` (Unicode's Final_Sigma context) and Qt as ``σ``; and
  ``str.casefold`` goes further (``ß`` as ``ss``, ``ﬁ`` as ``fi``), which Qt never does.

One key for every place that says what relight will list, so that none of them guesses its
own order.

Which Qt: this is Qt 5's ``qt_cmp_si`` (``filename_cache = fileName().toLower()``). Qt 6.8's
(the ``qdir.cpp`` read lists with ``QDirListing``; since which 6.x is not checked here) instead
compares ``fileName()`` by ``QString::compare(..., Qt::CaseInsensitive)``, each UTF-16 unit
simply case-folded (``ucstricmp``, ``foldCase``), and relight's CMakeLists builds with Qt 6
unless ``USE_QT_5``. The two orders agree on every name whose characters lower and fold
alike (ASCII, accented letters, Greek capitals, the tests' names) and differ on the few that
do not (``ς`` and ``ſ`` fold to ``σ`` and ``s`` but lower to themselves; Cherokee lower case
folds to upper): for those no one order is right for every relight build.
"""

from __future__ import annotations


def qt_name_key(name: str) -> tuple[bytes, bytes]:
    """The key QDir's ``Name | IgnoreCase`` sort orders ``name`` by: its characters lowered one
    at a time, as UTF-16 code units (big-endian bytes compare as the units do), then the name
    itself, alike, for names equal but for case (which Qt leaves in the order the folder
    gave them: no order can be known for those). A name read with ``surrogateescape`` (not
    UTF-8 on disk) keeps its lone surrogates."""
    lowered = "".join(c.lower() for c in name)
    return (
        lowered.encode("utf-16-be", "surrogatepass"),
        name.encode("utf-16-be", "surrogatepass"),
    )
