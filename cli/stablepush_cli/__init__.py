"""The `stablepush` command line: click commands over the stablepush Python API."""
