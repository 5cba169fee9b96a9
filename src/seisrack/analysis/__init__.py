"""seisrack.analysis"""
