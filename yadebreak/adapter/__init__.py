"""The one YADE adapter: yade_api.py is the only module of yadebreak that imports yade
(yadepath.py makes that import work from Debian's /usr/bin/python3)."""
