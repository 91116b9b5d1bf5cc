"""The classes of a body (`kind`, also the codes of the `class` column of outputs): breakable (1)
can break; unbreakable (2) is finer than dmin allows to break again and keeps the t10' of its
first would-be breakage; dummy (3) stands for the unresolved fines of an event and never breaks;
broken (4) was replaced. 0 marks ids yadebreak does not know. The engine's body table and the
criteria read the same codes."""

KINDS = ("none", "breakable", "unbreakable", "dummy", "broken")
NONE, BREAKABLE, UNBREAKABLE, DUMMY, BROKEN = range(5)
