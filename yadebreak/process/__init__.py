"""The process a run lives in, for every room: errors said in one line (errors), SIGINT and
SIGTERM stopping a run at its next stop point (signals), files written whole (files), child
processes that die with their parent (children). Pure Python: no yade, no numpy."""
