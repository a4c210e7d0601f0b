"""The models: one file each. `MODELS` maps a model name to its module."""
MODELS = {
    "torsion_gyrocompass": "derive.models.torsion_gyrocompass",
    "gimbal_gyroscope": "derive.models.gimbal_gyroscope",
}
