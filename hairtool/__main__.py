from hairtool.cli import entry

entry()
