"""Prints where the skybake module is installed, relative to the install prefix (argv[1]).

Debian's Python reads modules from lib/python3/dist-packages under /usr (packages) and from
lib/python3.X/dist-packages under /usr/local; another Python from its own site-packages.
"""
import sys
import sysconfig

prefix = sys.argv[1].rstrip("/")
if "deb_system" in sysconfig.get_scheme_names():
    if prefix == "/usr":
        print("lib/python3/dist-packages")
    else:
        print("lib/python%d.%d/dist-packages" % sys.version_info[:2])
else:
    print(sysconfig.get_path("platlib", "posix_prefix", vars={"base": "", "platbase": ""}).lstrip("/"))
