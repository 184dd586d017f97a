"""A pandas stand-in for the Spark calls of docs/python.md's Spark block (Spark itself
is not installed here): ``spark.read.parquet``, ``repartition``,
``sortWithinPartitions``, ``mapInPandas`` and the schema types, with Spark's contract
for ``mapInPandas``: the function gets a partition as an iterator of pandas batches of
at most ``maxRecordsPerBatch`` rows, and what it yields must have the schema's
columns. Importing it installs ``pyspark.sql.types`` as this module's classes."""

import sys
import types

import pandas as pd

MAX_RECORDS_PER_BATCH = 1000  # small, so that a roller spans several batches


class _Type:
    pass


class StringType(_Type):
    pass


class LongType(_Type):
    pass


class DoubleType(_Type):
    pass


class StructField:
    def __init__(self, name, dtype):
        self.name, self.dtype = name, dtype


class StructType:
    def __init__(self, fields):
        self.fields = list(fields)


class Frame:
    def __init__(self, partitions):
        self.partitions = partitions

    def repartition(self, column):
        whole = pd.concat(self.partitions, ignore_index=True)
        return Frame([g for _, g in whole.groupby(column, sort=False)])

    def sortWithinPartitions(self, *columns):
        return Frame([p.sort_values(list(columns), kind="stable") for p in self.partitions])

    def mapInPandas(self, function, schema):
        names = [f.name for f in schema.fields]
        out = []
        for p in self.partitions:
            batches = (p.iloc[i:i + MAX_RECORDS_PER_BATCH].reset_index(drop=True)
                       for i in range(0, len(p), MAX_RECORDS_PER_BATCH))
            for result in function(batches):
                if list(result.columns) != names:
                    raise ValueError(f"columns {list(result.columns)} are not the schema's")
                out.append(result)
        return Frame(out)

    def toPandas(self):
        return pd.concat(self.partitions, ignore_index=True)


class _Reader:
    def parquet(self, path):
        return Frame([pd.read_parquet(path)])


class _Session:
    read = _Reader()


spark = _Session()

_types = types.ModuleType("pyspark.sql.types")
for _name in ["StringType", "LongType", "DoubleType", "StructField", "StructType"]:
    setattr(_types, _name, globals()[_name])
sys.modules.setdefault("pyspark", types.ModuleType("pyspark"))
sys.modules.setdefault("pyspark.sql", types.ModuleType("pyspark.sql"))
sys.modules["pyspark.sql.types"] = _types
