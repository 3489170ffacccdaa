"""duan2023's SINS/ADS error-correction method.
"""
