"""seisrack.sdof"""
