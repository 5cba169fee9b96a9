"""seisrack.report"""
